#pragma once
// Errors that reach the user, one class per exit code (docs/reference/running.md, "Exit codes"). Every failure
// caused by input (a file, a parameter, a mesh that violates an assumption) is an InputError whose
// message says where and what was expected; a velocity model that fails is a PluginError naming the
// model, the iteration and the stage; a computation that cannot go on (a non-finite value, a bound
// reached) is a NumericalError; a file that cannot be written is an IoError. The driver prints the
// message on one line and exits with the class's code.
#include <filesystem>
#include <stdexcept>
#include <string>

namespace bodyfit {

/// The process exit codes, one per class of failure.
enum class ExitCode : int {
  Ok = 0,
  Input = 1,        ///< a file, case, `--set` value or mesh the run cannot accept
  Usage = 2,        ///< the command line itself (unknown option, missing argument)
  Internal = 3,     ///< a bug: an exception bodyfit did not expect
  Plugin = 4,       ///< a velocity model failed (exception, non-finite or wrong-sized output, crash)
  Numerical = 5,    ///< a computation that cannot go on (non-finite values, an iteration bound reached)
  Io = 6,           ///< an output that cannot be written (permissions, disk full)
  Interrupted = 130 ///< SIGINT / SIGTERM: the run stopped after writing a checkpoint (128 + SIGINT)
};

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class PluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The exit code of an exception: its class's, ExitCode::Internal for any other.
ExitCode exit_code_of(const std::exception& e);

/// "<file>:<line>: <what>" — the message of an error located in a text file.
InputError file_error(const std::filesystem::path& file, long line, const std::string& what);
/// "<file>: <what>" — an error that concerns a file as a whole (or a byte offset given in `what`).
InputError file_error(const std::filesystem::path& file, const std::string& what);
/// "<file>: <what>" — an output that cannot be written (ExitCode::Io).
IoError write_error(const std::filesystem::path& file, const std::string& what);

}  // namespace bodyfit
