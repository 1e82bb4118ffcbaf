#include <bodyfit/error.hpp>

#include <fmt/format.h>

namespace bodyfit {

InputError file_error(const std::filesystem::path& file, long line, const std::string& what) {
  return InputError(fmt::format("{}:{}: {}", file.string(), line, what));
}

InputError file_error(const std::filesystem::path& file, const std::string& what) {
  return InputError(fmt::format("{}: {}", file.string(), what));
}

}  // namespace bodyfit
