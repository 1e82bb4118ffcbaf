#pragma once
// Errors that reach the user. Every failure caused by input (a file, a parameter, a mesh that
// violates an assumption) is an InputError whose message says where and what was expected; the
// driver prints it on one line and exits with a non-zero code.
#include <filesystem>
#include <stdexcept>
#include <string>

namespace bodyfit {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "<file>:<line>: <what>" — the message of an error located in a text file.
InputError file_error(const std::filesystem::path& file, long line, const std::string& what);
/// "<file>: <what>" — an error that concerns a file as a whole (or a byte offset given in `what`).
InputError file_error(const std::filesystem::path& file, const std::string& what);

}  // namespace bodyfit
