#include <bodyfit/error.hpp>

#include <fmt/format.h>

namespace bodyfit {

ExitCode exit_code_of(const std::exception& e) {
  if (dynamic_cast<const InputError*>(&e)) return ExitCode::Input;
  if (dynamic_cast<const PluginError*>(&e)) return ExitCode::Plugin;
  if (dynamic_cast<const NumericalError*>(&e)) return ExitCode::Numerical;
  if (dynamic_cast<const IoError*>(&e)) return ExitCode::Io;
  // std::filesystem operations of the drivers (creating an output directory, removing a stale
  // file): the reading side checks its files itself, so what is left is writing.
  if (dynamic_cast<const std::filesystem::filesystem_error*>(&e)) return ExitCode::Io;
  return ExitCode::Internal;
}

InputError file_error(const std::filesystem::path& file, long line, const std::string& what) {
  return InputError(fmt::format("{}:{}: {}", file.string(), line, what));
}

InputError file_error(const std::filesystem::path& file, const std::string& what) {
  return InputError(fmt::format("{}: {}", file.string(), what));
}

IoError write_error(const std::filesystem::path& file, const std::string& what) {
  return IoError(fmt::format("{}: {}", file.string(), what));
}

}  // namespace bodyfit
