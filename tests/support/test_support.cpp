#include "test_support.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace bodyfit::test {

TempDir::TempDir(const std::string& name) {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::path(BODYFIT_BINARY_DIR) / "test-tmp" /
          (name + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::string history_without_timings(const std::filesystem::path& file) {
  std::stringstream in(read_file(file)), out;
  std::vector<bool> keep;
  for (std::string line; std::getline(in, line);) {
    std::stringstream cells(line);
    std::size_t c = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++c) {
      if (keep.size() <= c) keep.push_back(cell.rfind("ms_", 0) != 0);  // from the header
      if (keep[c]) out << cell << ',';
    }
    out << '\n';
  }
  return out.str();
}

CommandResult run_bodyfit(const std::string& arguments) {
  std::string command = std::string("\"") + BODYFIT_EXE + "\" " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.output.append(buffer.data(), n);
  int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

SurfaceMesh grid_square(int n, const GridSquare& o) {
  SurfaceMesh mesh;
  std::vector<VertexHandle> v;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      v.push_back(mesh.add_vertex(Vec3(o.x0 + (o.x1 - o.x0) * i / n, o.y0 + (o.y1 - o.y0) * j / n, 0)));
  auto at = [&](int i, int j) { return v[std::size_t(j * (n + 1) + i)]; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (!o.alternate_diagonals || (i + j) % 2 == 0) {
        mesh.add_face(at(i, j), at(i + 1, j), at(i + 1, j + 1));
        mesh.add_face(at(i, j), at(i + 1, j + 1), at(i, j + 1));
      } else {
        mesh.add_face(at(i, j), at(i + 1, j), at(i, j + 1));
        mesh.add_face(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
    }
  return mesh;
}

std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(BODYFIT_SOURCE_DIR) / relative;
}

std::vector<double> csv_column(const std::filesystem::path& file, const std::string& name) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  auto cells = [](const std::string& text) {
    std::vector<std::string> out;
    std::stringstream s(text);
    for (std::string cell; std::getline(s, cell, ',');) out.push_back(cell);
    return out;
  };
  const std::vector<std::string> header = cells(line);
  const auto at = std::size_t(std::find(header.begin(), header.end(), name) - header.begin());
  if (at == header.size()) throw std::runtime_error(file.string() + ": no column " + name);
  std::vector<double> values;
  while (std::getline(in, line))
    if (!line.empty()) values.push_back(std::stod(cells(line).at(at)));
  return values;
}

std::string utm_prj(int zone) {
  return fmt::format(
      "PROJCS[\"WGS_1984_UTM_Zone_{}N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\","
      "6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]],PROJECTION["
      "\"Transverse_Mercator\"],PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",0.0],"
      "PARAMETER[\"Central_Meridian\",{}.0],PARAMETER[\"Scale_Factor\",0.9996],PARAMETER[\"Latitude_Of_Origin\","
      "0.0],UNIT[\"Meter\",1.0]]",
      zone, 6 * zone - 183);
}

}  // namespace bodyfit::test
