// Wavefront OBJ, read by bodyfit itself into the validated builder (OpenMesh's reader failed an
// assertion on a malformed face: tests/fuzz/regressions/openmesh-obj-assert-face). Only the
// geometry a surface needs is read: `v x y z [w | r g b]` and `f` with corners v, v/vt, v//vn or
// v/vt/vn, 1-based or negative (relative to the last vertex read); a polygon becomes triangles
// (io_polygon.hpp). Texture coordinates, normals, groups, objects, materials, smoothing groups, lines and
// points are skipped; any other keyword is an error naming its line. A line ending in '\' goes on
// on the next one.
#include "io_text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace bodyfit::io_detail {
namespace {

/// Keywords read and skipped: attributes of vertices and faces that a surface mesh does not keep.
constexpr std::array<std::string_view, 13> kSkipped{
    "vt", "vn", "vp", "o", "g", "s", "usemtl", "mtllib", "l", "p", "maplib", "usemap", "lod"};

/// Whether `keyword` is one of OBJ's free-form geometry statements (curves and surfaces).
bool free_form(std::string_view keyword) {
  constexpr std::array<std::string_view, 14> words{
      "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con"};
  return std::find(words.begin(), words.end(), keyword) != words.end();
}

/// One corner of a face: "v", "v/vt", "v//vn" or "v/vt/vn" → the 0-based vertex index, given the
/// number of vertices read so far. Throws with the line for anything else.
std::int64_t corner_index(std::string_view word, std::int64_t vertices, std::size_t face, const std::filesystem::path& file,
                          long line) {
  const std::size_t slash = word.find('/');
  const std::string_view vertex = word.substr(0, slash);
  std::int64_t index = 0;
  bool ok = parse_number(vertex, index) && index != 0;
  if (ok && slash != std::string_view::npos) {
    // The texture and normal indices are not used, but must be indices (vt may be empty: v//vn).
    const std::string_view rest = word.substr(slash + 1);
    const std::size_t second = rest.find('/');
    const std::string_view texture = rest.substr(0, second);
    std::int64_t unused = 0;
    if (second == std::string_view::npos) {
      ok = parse_number(texture, unused);
    } else {
      const std::string_view normal = rest.substr(second + 1);
      ok = (texture.empty() || parse_number(texture, unused)) && parse_number(normal, unused);
    }
  }
  if (!ok)
    throw file_error(file, line,
                     fmt::format("face {}: corner '{}' is not v, v/vt, v//vn or v/vt/vn with non-zero integer indices",
                                 face, word.substr(0, 40)));
  // Positive: 1-based; negative: -1 is the last vertex read so far.
  const std::int64_t zero_based = index > 0 ? index - 1 : vertices + index;
  if (zero_based < 0 || zero_based >= vertices)
    throw file_error(file, line,
                     fmt::format("face {}: vertex index {} is out of range: {} vertices are defined before this line "
                                 "(expected 1 to {} or -1 to -{})",
                                 face, index, vertices, vertices, vertices));
  return zero_based;
}

}  // namespace

MeshRecords parse_obj(std::string_view bytes, const std::filesystem::path& file) {
  MeshRecords records;
  records.vertex_at = records.triangle_at = Locator::lines();
  std::vector<std::int64_t> corners;
  std::string joined;  // a statement continued over several lines ('\' at their ends)
  std::size_t faces = 0;
  Lines lines(bytes);
  while (const std::optional<std::string_view> line = lines.next_statement(joined)) {
    const long line_number = lines.first_number();
    Words words(*line);
    const std::string_view keyword = words.next();
    if (keyword.empty()) continue;
    if (keyword == "v") {
      double x[3];
      for (double& c : x) {
        const std::string_view w = words.next();
        if (!parse_number(w, c))
          throw file_error(file, line_number,
                           w.empty() ? fmt::format("vertex {}: expected 3 coordinates", records.points.size() + 1)
                                     : fmt::format("vertex {}: '{}' is not a number", records.points.size() + 1,
                                                   w.substr(0, 40)));
      }
      // Optional: a weight w, or a colour r g b (a common extension). Numbers, at most four.
      int extra = 0;
      for (std::string_view w = words.next(); !w.empty(); w = words.next(), ++extra) {
        double unused = 0;
        if (extra == 4 || !parse_number(w, unused))
          throw file_error(file, line_number,
                           fmt::format("vertex {}: unexpected '{}' after the coordinates (expected at most a weight "
                                       "or an r g b colour)",
                                       records.points.size() + 1, w.substr(0, 40)));
      }
      if (records.points.size() >= std::size_t(INT32_MAX))
        throw file_error(file, line_number, "more than 2^31 - 1 vertices");
      records.points.push_back(Vec3(x[0], x[1], x[2]));
      records.vertex_at.push_line(line_number);
    } else if (keyword == "f") {
      ++faces;
      corners.clear();
      const auto vertices = std::int64_t(records.points.size());
      for (std::string_view w = words.next(); !w.empty(); w = words.next())
        corners.push_back(corner_index(w, vertices, faces, file, line_number));
      if (corners.size() < 3)
        throw file_error(file, line_number,
                         fmt::format("face {} has {} corners, expected at least 3", faces, corners.size()));
      if (!add_polygon(records, corners.data(), std::int64_t(corners.size()), line_number))
        throw file_error(file, line_number, fmt::format("face {}: a polygon of {} corners whose outline crosses itself or has no area cannot be triangulated", faces, corners.size()));
    } else if (std::find(kSkipped.begin(), kSkipped.end(), keyword) != kSkipped.end()) {
      continue;
    } else if (free_form(keyword)) {
      throw file_error(file, line_number,
                       fmt::format("'{}': OBJ free-form curves and surfaces are not supported (only polygons: v, f)",
                                   keyword));
    } else {
      throw file_error(file, line_number,
                       fmt::format("'{}' is not an OBJ statement (expected v or f; vt, vn, vp, o, g, s, usemtl, mtllib, "
                                   "l, p are skipped)",
                                   keyword.substr(0, 40)));
    }
  }
  return records;
}

SurfaceMesh read_obj(const std::filesystem::path& file, const ReadOptions& options) {
  const FileBytes bytes(file);
  return build_mesh(parse_obj(bytes.view(), file), file, options);
}

}  // namespace bodyfit::io_detail
