#pragma once
// Private to the io_*.cpp files: the validated mesh builder every reader goes through, and the
// locations used in error messages ("line N" for text files, "byte N" for binary ones).
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit::io_detail {

/// Where record i of a section starts: a line per record (text) or start + i·stride bytes (binary).
class Locator {
 public:
  static Locator lines() { return Locator(); }
  static Locator bytes(std::uint64_t start, std::uint64_t stride) {
    Locator l;
    l.binary_ = true;
    l.start_ = start;
    l.stride_ = stride;
    return l;
  }
  static Locator none() {
    Locator l;
    l.none_ = true;
    return l;
  }
  void push_line(long line) {
    if (!binary_ && !none_) lines_.push_back(static_cast<std::uint32_t>(line));
  }
  void reserve(std::size_t n) {
    if (!binary_ && !none_) lines_.reserve(n);
  }
  /// The error for record i: "<file>:<line>: what", "<file>: byte N: what" or "<file>: what".
  InputError error(const std::filesystem::path& file, std::size_t i, const std::string& what) const;

 private:
  bool binary_ = false;
  bool none_ = false;
  std::uint64_t start_ = 0, stride_ = 0;
  std::vector<std::uint32_t> lines_;
};

/// A mesh as read from a file, before validation. Indices are 0-based.
struct MeshRecords {
  std::vector<Vec3> points;
  std::vector<int> vertex_refs;
  Locator vertex_at;
  std::vector<std::array<std::int64_t, 3>> triangles;
  std::vector<int> triangle_refs;
  Locator triangle_at;
  std::vector<std::array<std::int64_t, 2>> edges;
  std::vector<int> edge_refs;
  Locator edge_at;
  // Indices (0-based) into points or edges; each with its own locator.
  std::vector<std::int64_t> corners, required_vertices, ridges, required_edges;
  Locator corner_at, required_vertex_at, ridge_at, required_edge_at;
};

/// Check everything (finite coordinates, indices in range, no degenerate, duplicate or zero-area
/// triangle, manifold edges and vertices, consistent orientation) and build the mesh with its
/// refs and tags. Throws InputError located with the records' locators.
SurfaceMesh build_mesh(MeshRecords&& records, const std::filesystem::path& file, const ReadOptions& options);

/// Lower-case extension with its dot (".mesh").
std::string extension_of(const std::filesystem::path& file);

/// The whole file in memory; InputError when it cannot be opened or read.
std::string read_file_bytes(const std::filesystem::path& file);

/// Compact vertex indices (skipping deleted vertices): index[v.idx()] = position in the output.
std::vector<std::int64_t> vertex_numbering(const SurfaceMesh& mesh);

// Per-format entry points.
SurfaceMesh read_medit(const std::filesystem::path& file, const ReadOptions& options);
void write_medit(const SurfaceMesh& mesh, const std::filesystem::path& file, bool binary);
SurfaceMesh read_openmesh_format(const std::filesystem::path& file, const ReadOptions& options);
void write_openmesh_format(const SurfaceMesh& mesh, const std::filesystem::path& file);

}  // namespace bodyfit::io_detail
