// OFF (Geomview's Object File Format), read by bodyfit itself into the validated builder, as Medit
// files are: OpenMesh's reader trusted the file's numbers and looped on malformed faces
// (tests/fuzz/regressions). Text OFF is read a record per line — a vertex line holds its
// coordinates and then optional normal, colour and texture numbers, a face line its corner count,
// its corners and an optional colour — so every error names its line. Binary OFF ("OFF BINARY") is
// big-endian as Geomview writes it; a file whose counts only fit the other byte order is read in it.
#include "io_text.hpp"

#include <fmt/format.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <utility>
#include <vector>

namespace bodyfit::io_detail {
namespace {

/// What the keyword "[ST][C][N][4][n]OFF" says a vertex record holds.
struct OffLayout {
  bool homogeneous = false;  ///< '4': x y z w
  bool normals = false, colours = false, texture = false;
  bool dimension_given = false;  ///< 'n': a dimension precedes the counts
  /// Floats of one binary vertex record.
  int binary_floats() const { return 3 + homogeneous + 3 * normals + 4 * colours + 2 * texture; }
};

std::optional<OffLayout> parse_keyword(std::string_view word) {
  OffLayout layout;
  auto take = [&](std::string_view prefix) {
    if (!word.starts_with(prefix)) return false;
    word.remove_prefix(prefix.size());
    return true;
  };
  layout.texture = take("ST");
  layout.colours = take("C");
  layout.normals = take("N");
  layout.homogeneous = take("4");
  layout.dimension_given = take("n");
  if (word != "OFF") return std::nullopt;
  return layout;
}

/// A count of the header: a non-negative integer below 2³¹.
std::int64_t header_count(std::string_view word, const std::filesystem::path& file, long line, const char* what) {
  std::int64_t value = -1;
  if (word.empty()) throw file_error(file, line, fmt::format("expected the {} after 'OFF'", what));
  if (!parse_number(word, value) || value < 0)
    throw file_error(file, line, fmt::format("the header's {} '{}' is not a count (a non-negative integer)", what, word));
  return value;
}

MeshRecords parse_text(std::string_view bytes, const OffLayout& layout, Lines& lines, Words& rest,
                       const std::filesystem::path& file) {
  // The dimension and the counts follow the keyword, on its line or the next ones.
  std::string_view word = rest.next();
  auto next_word = [&]() -> std::string_view {
    while (word.empty()) {
      const auto line = lines.next();
      if (!line) return {};
      rest = Words(*line);
      word = rest.next();
    }
    return std::exchange(word, rest.next());
  };
  if (layout.dimension_given) {
    const std::int64_t dimension = header_count(next_word(), file, lines.number(), "dimension");
    if (dimension != 3)
      throw file_error(file, lines.number(), fmt::format("vertices of dimension {}: only 3 is supported", dimension));
  }
  const std::int64_t vertices = header_count(next_word(), file, lines.number(), "vertex count");
  const std::int64_t faces = header_count(next_word(), file, lines.number(), "face count");
  check_counts_fit(std::uint64_t(vertices), std::uint64_t(faces), 6, 8, bytes.size(), file);  // "0 0 0\n", "3 0 1 2\n"
  // (The edge count, when given, is unused: the faces say it.)

  MeshRecords records;
  records.vertex_at = records.triangle_at = Locator::lines();
  records.points.reserve(std::size_t(vertices));
  records.vertex_at.reserve(std::size_t(vertices));
  records.triangles.reserve(std::size_t(faces));
  records.triangle_at.reserve(std::size_t(faces));
  const int coordinates = layout.homogeneous ? 4 : 3;
  for (std::int64_t v = 0; v < vertices; ++v) {
    const auto line = lines.next();
    if (!line)
      throw file_error(file, lines.number(),
                       fmt::format("the file ends after {} of its {} vertices (truncated?)", v, vertices));
    Words numbers(*line);
    double x[4] = {0, 0, 0, 1};
    for (int c = 0; c < coordinates; ++c) {
      const std::string_view w = numbers.next();
      if (!parse_number(w, x[c]))
        throw file_error(file, lines.number(),
                         w.empty() ? fmt::format("vertex {}: expected {} coordinates", v + 1, coordinates)
                                   : fmt::format("vertex {}: '{}' is not a number", v + 1, w));
    }
    if (layout.homogeneous) {
      if (!(x[3] != 0) || !std::isfinite(x[3]))
        throw file_error(file, lines.number(), fmt::format("vertex {}: homogeneous weight {} (expected non-zero)", v + 1, x[3]));
      for (int c = 0; c < 3; ++c) x[c] /= x[3];
    }
    records.points.push_back(Vec3(x[0], x[1], x[2]));
    records.vertex_at.push_line(lines.number());
  }
  std::vector<std::int64_t> corners;
  for (std::int64_t f = 0; f < faces; ++f) {
    const auto line = lines.next();
    if (!line)
      throw file_error(file, lines.number(), fmt::format("the file ends after {} of its {} faces (truncated?)", f, faces));
    Words numbers(*line);
    const std::string_view first = numbers.next();
    std::int64_t count = 0;
    if (!parse_number(first, count))
      throw file_error(file, lines.number(), fmt::format("face {}: '{}' is not a corner count", f + 1, first));
    if (count < 3 || count > vertices)
      throw file_error(file, lines.number(),
                       fmt::format("face {} has {} corners, expected 3 to {} (the number of vertices)", f + 1, count,
                                   vertices));
    corners.resize(std::size_t(count));
    for (std::int64_t& c : corners) {
      const std::string_view w = numbers.next();
      if (!parse_number(w, c) || c < 0 || c >= vertices)
        throw file_error(file, lines.number(),
                         w.empty() ? fmt::format("face {}: expected {} corners", f + 1, count)
                                   : fmt::format("face {}: corner '{}' is not a vertex index (0 to {})", f + 1, w,
                                                 vertices - 1));
    }
    if (!add_polygon(records, corners.data(), count, lines.number()))
      throw file_error(file, lines.number(), fmt::format("face {}: a polygon of {} corners whose outline crosses itself or has no area cannot be triangulated", f + 1, count));
  }
  return records;
}

/// Geomview's binary OFF: 32-bit counts, float vertices, faces as (k, k corners, colour count, colours).
MeshRecords parse_binary(std::string_view bytes, std::size_t start, const OffLayout& layout,
                         const std::filesystem::path& file) {
  const std::uint64_t size = bytes.size();
  if (size < start + 12) throw file_error(file, "binary OFF: the header's three counts are cut short");
  const int vertex_floats = layout.binary_floats();
  auto word_at = [&](std::size_t at, bool little_endian) {
    std::uint32_t w = 0;
    std::memcpy(&w, bytes.data() + at, 4);
    return little_endian == (std::endian::native == std::endian::little) ? w : __builtin_bswap32(w);
  };
  // Big-endian as the format says, unless only the little-endian reading fits the file.
  auto fits = [&](bool little) {
    const double needed = double(word_at(start, little)) * 4.0 * vertex_floats + double(word_at(start + 4, little)) * 16.0;
    return needed <= double(size - start - 12);
  };
  const bool little = !fits(false) && fits(true);
  const std::int64_t vertices = word_at(start, little), faces = word_at(start + 4, little);
  if (vertices > INT32_MAX || faces > INT32_MAX)
    throw file_error(file, fmt::format("binary OFF: the header declares {} vertices and {} faces", vertices, faces));
  check_counts_fit(std::uint64_t(vertices), std::uint64_t(faces), 4.0 * vertex_floats, 16, size - start - 12, file);

  MeshRecords records;
  const std::size_t vertex_start = start + 12, stride = std::size_t(4 * vertex_floats);
  records.vertex_at = Locator::bytes(vertex_start, stride);
  records.triangle_at = Locator::none();
  records.points.reserve(std::size_t(vertices));
  auto float_at = [&](std::size_t at) { return std::bit_cast<float>(word_at(at, little)); };
  for (std::int64_t v = 0; v < vertices; ++v) {
    const std::size_t at = vertex_start + std::size_t(v) * stride;
    double x[4] = {float_at(at), float_at(at + 4), float_at(at + 8), layout.homogeneous ? float_at(at + 12) : 1.0};
    if (layout.homogeneous) {
      if (!(x[3] != 0) || !std::isfinite(x[3]))
        throw file_error(file, fmt::format("binary OFF: vertex {} has the homogeneous weight {}", v + 1, x[3]));
      for (int c = 0; c < 3; ++c) x[c] /= x[3];
    }
    records.points.push_back(Vec3(x[0], x[1], x[2]));
  }
  std::size_t at = vertex_start + std::size_t(vertices) * stride;
  std::vector<std::int64_t> corners;
  for (std::int64_t f = 0; f < faces; ++f) {
    auto need = [&](std::uint64_t n, const char* what) {
      if (at + n > size)
        throw file_error(file, fmt::format("binary OFF: byte {}: the file ends within face {} ({}; truncated?)", at,
                                           f + 1, what));
    };
    need(4, "its corner count");
    const std::int64_t count = std::int32_t(word_at(at, little));
    if (count < 3 || count > vertices)
      throw file_error(file, fmt::format("binary OFF: byte {}: face {} has {} corners, expected 3 to {} (the number of "
                                         "vertices)",
                                         at, f + 1, count, vertices));
    need(4 * std::uint64_t(count) + 8, "its corners and colour count");
    corners.resize(std::size_t(count));
    for (std::int64_t i = 0; i < count; ++i) corners[std::size_t(i)] = std::int32_t(word_at(at + 4 + 4 * i, little));
    at += 4 + 4 * std::size_t(count);
    const std::int64_t colours = std::int32_t(word_at(at, little));
    if (colours < 0 || colours > 4)
      throw file_error(file, fmt::format("binary OFF: byte {}: face {} has {} colour components, expected 0 to 4", at,
                                         f + 1, colours));
    at += 4;
    need(4 * std::uint64_t(colours), "its colour");
    at += 4 * std::size_t(colours);
    if (!add_polygon(records, corners.data(), count, 0))
      throw file_error(file, fmt::format("binary OFF: face {}: a polygon of {} corners whose outline crosses itself or has no area cannot be triangulated", f + 1, count));
  }
  return records;
}

}  // namespace

MeshRecords parse_off(std::string_view bytes, const std::filesystem::path& file) {
  Lines lines(bytes);
  const auto first = lines.next();
  Words words(first.value_or(std::string_view()));
  const std::string_view keyword = words.next();
  const auto layout = parse_keyword(keyword);
  if (!layout) throw file_error(file, "not an OFF file: it does not start with 'OFF' (or [ST][C][N][4][n]OFF)");
  Words after = words;
  if (after.next() == "BINARY") {
    // The binary records start after the newline that ends the keyword's line.
    return parse_binary(bytes, lines.offset(), *layout, file);
  }
  return parse_text(bytes, *layout, lines, words, file);
}

SurfaceMesh read_off(const std::filesystem::path& file, const ReadOptions& options) {
  const FileBytes bytes(file);
  return build_mesh(parse_off(bytes.view(), file), file, options);
}

}  // namespace bodyfit::io_detail
