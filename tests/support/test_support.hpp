#pragma once
// Shared helpers of the test suite: temporary directories, running the bodyfit executable.
#include <filesystem>
#include <string>

namespace bodyfit::test {

/// A fresh directory under the build tree, removed at the end of the scope.
class TempDir {
 public:
  explicit TempDir(const std::string& name);
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = 0;
  std::string output;  ///< stdout and stderr together
};
/// Run `bodyfit <arguments>` and capture its output.
CommandResult run_bodyfit(const std::string& arguments);

/// Path of a file in the source tree (e.g. "meshes/cube.mesh").
std::filesystem::path source_path(const std::string& relative);

}  // namespace bodyfit::test
