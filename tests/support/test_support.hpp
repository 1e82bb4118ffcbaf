#pragma once
// Shared helpers of the test suite: temporary directories, running the bodyfit executable.
#include <bodyfit/mesh.hpp>

#include <filesystem>
#include <string>
#include <vector>

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

/// A flat n×n grid of squares over [x0, x1]×[y0, y1] (z = 0), each split into two triangles along
/// the same diagonal, or along alternating diagonals (a symmetric "union jack"-like pattern).
struct GridSquare {
  double x0 = 0, y0 = 0, x1 = 1, y1 = 1;
  bool alternate_diagonals = false;
};
SurfaceMesh grid_square(int n, const GridSquare& options = {});

/// The bytes of a file ("" when it cannot be read).
std::string read_file(const std::filesystem::path& file);

/// history.csv without its wall-clock columns (ms_*), which no two runs share.
std::string history_without_timings(const std::filesystem::path& file);

/// Path of a file in the source tree (e.g. "meshes/parts/bracket_h0.07.mesh").
std::filesystem::path source_path(const std::string& relative);

/// The values of the column `name` of a CSV file with a header row (a run's history.csv, an
/// ensemble's members.csv), as numbers.
std::vector<double> csv_column(const std::filesystem::path& file, const std::string& name);

/// The ESRI WKT (.prj) of WGS 84 / UTM zone `zone` N.
std::string utm_prj(int zone);

}  // namespace bodyfit::test
