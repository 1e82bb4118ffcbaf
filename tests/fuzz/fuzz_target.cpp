// A libFuzzer target: the reader of BODYFIT_FUZZ_TARGET (fuzz_inputs.hpp) on every input.
// InputError is the expected end of bad input; anything else escapes and libFuzzer reports it.
#include "fuzz_inputs.hpp"

#include <bodyfit/error.hpp>

#include <spdlog/spdlog.h>

#include <cstddef>
#include <cstdint>

namespace {
const bodyfit::fuzz::Reader reader = bodyfit::fuzz::reader_named(BODYFIT_FUZZ_TARGET);
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_level(spdlog::level::off);  // readers' warnings, once per input, would drown the fuzzer's log
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    bodyfit::fuzz::read_input(reader, {reinterpret_cast<const char*>(data), size});
  } catch (const bodyfit::InputError&) {
  }
  return 0;
}
