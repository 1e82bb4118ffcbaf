// Inputs the fuzzers of tests/fuzz found to crash, hang or leak a reader (docs/reference/testing.md), kept in
// tests/fuzz/regressions/<target>-<what>: each must now end in a clean InputError, in every build
// (the sanitizer stage of scripts/run_tests.sh replays them under ASan and UBSan too).
#include "fuzz_inputs.hpp"

#include <bodyfit/error.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;

TEST_CASE("fuzz regressions: every input the fuzzers found ends in an InputError") {
  std::vector<fs::path> inputs;
  for (const auto& entry : fs::directory_iterator(BODYFIT_FUZZ_REGRESSIONS))
    if (entry.is_regular_file() && entry.path().filename() != "README.md") inputs.push_back(entry.path());
  std::sort(inputs.begin(), inputs.end());
  for (const auto& input : inputs) {
    const std::string name = input.filename().string();
    CAPTURE(name);
    const auto target = name.substr(0, name.find('-'));
    const auto reader = bodyfit::fuzz::reader_named(target);
    const std::string bytes = bodyfit::test::read_file(input);
    REQUIRE_FALSE(bytes.empty());
    CHECK_THROWS_AS(bodyfit::fuzz::read_input(reader, bytes), bodyfit::InputError);
  }
}
