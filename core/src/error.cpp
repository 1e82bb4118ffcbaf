#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <new>

namespace bodyfit {

ExitCode exit_code_of(const std::exception& e) {
  if (dynamic_cast<const InputError*>(&e)) return ExitCode::Input;
  if (dynamic_cast<const PluginError*>(&e)) return ExitCode::Plugin;
  if (dynamic_cast<const NumericalError*>(&e)) return ExitCode::Numerical;
  if (dynamic_cast<const IoError*>(&e)) return ExitCode::Io;
  // std::filesystem operations of the drivers (creating an output directory, removing a stale
  // file): the reading side checks its files itself, so what is left is writing.
  if (dynamic_cast<const std::filesystem::filesystem_error*>(&e)) return ExitCode::Io;
  // Memory exhausted: not a bug, but more than this machine holds for what was asked (the size
  // estimates refuse what they can foresee; --max-faces).
  if (dynamic_cast<const std::bad_alloc*>(&e)) return ExitCode::Input;
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
