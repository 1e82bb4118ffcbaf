#pragma once
// Private to the text readers (io_off.cpp, io_obj.cpp, io_ply.cpp): lines with their numbers,
// the words of a line, numbers parsed whole, polygons as fans, counts checked against the length.
#include "io_internal.hpp"
#include "io_polygon.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

namespace bodyfit::io_detail {

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// The lines of a text file with '#' comments removed, empty ones skipped, numbered from 1.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}
  /// The next non-empty line (without its comment), or nullopt at the end.
  std::optional<std::string_view> next() {
    while (at_ < text_.size()) {
      const std::string_view line = read_line();
      if (line.find_first_not_of(" \t\r\f\v") != std::string_view::npos) return line;
    }
    return std::nullopt;
  }
  /// As next(), for a format whose statements go on over the following lines while a line ends
  /// with '\' (OBJ): those lines are joined with spaces into `joined`, which the view returned then
  /// points into; first_number() is the number of the statement's first line. Trailing blanks are
  /// removed. Each line is read once, so a statement is bounded by the file.
  std::optional<std::string_view> next_statement(std::string& joined) {
    std::optional<std::string_view> line = next();
    first_number_ = number_;
    if (!line) return line;
    const std::string_view text = trim_end(*line);
    if (text.back() != '\\') return text;
    joined.assign(text.substr(0, text.size() - 1));
    while (at_ < text_.size()) {
      const std::string_view more = trim_end(read_line());
      const bool continues = !more.empty() && more.back() == '\\';
      joined += ' ';
      joined.append(more.substr(0, more.size() - (continues ? 1 : 0)));
      if (!continues) break;
    }
    return std::string_view(joined);
  }
  long number() const { return number_; }
  long first_number() const { return first_number_; }
  std::size_t offset() const { return std::min(at_, text_.size()); }

 private:
  /// The next line, without its comment (possibly empty).
  std::string_view read_line() {
    const std::size_t end = std::min(text_.find('\n', at_), text_.size());
    std::string_view line = text_.substr(at_, end - at_);
    at_ = end + 1;
    ++number_;
    return line.substr(0, line.find('#'));
  }
  static std::string_view trim_end(std::string_view line) {
    while (!line.empty() && is_blank(line.back())) line.remove_suffix(1);
    return line;
  }

  std::string_view text_;
  std::size_t at_ = 0;
  long number_ = 0, first_number_ = 0;
};

/// Whitespace-separated words of one line.
class Words {
 public:
  explicit Words(std::string_view line) : line_(line) {}
  std::string_view next() {
    while (at_ < line_.size() && is_blank(line_[at_])) ++at_;
    const std::size_t start = at_;
    while (at_ < line_.size() && !is_blank(line_[at_])) ++at_;
    return line_.substr(start, at_ - start);
  }

 private:
  std::string_view line_;
  std::size_t at_ = 0;
};

/// `word` as a whole number of type T (a leading '+' allowed); false if any of it is not.
template <class T>
bool parse_number(std::string_view word, T& value) {
  if (word.size() > 1 && word[0] == '+' && word[1] != '-') word.remove_prefix(1);
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  return error == std::errc() && end == word.data() + word.size();
}

/// Each record takes at least a few bytes: counts the file cannot hold are an error before any
/// memory is reserved for them (a damaged header is not a 137 GB allocation).
inline void check_counts_fit(std::uint64_t vertices, std::uint64_t faces, double vertex_bytes, double face_bytes,
                             std::uint64_t size, const std::filesystem::path& file) {
  const double needed = double(vertices) * vertex_bytes + double(faces) * face_bytes;
  if (needed > double(size))
    throw file_error(file, fmt::format("the header declares {} vertices and {} faces, which need at least {:.0f} bytes; "
                                       "the file has {} (truncated or not this format?)",
                                       vertices, faces, needed, size));
}

/// A face of `count` corners as triangles: a triangle as it is, a polygon clipped ear by ear
/// (io_polygon.hpp); `line` is where it was read (ignored by a locator that has no lines). False
/// when the polygon's outline cannot be triangulated (the caller names the face). Corners not read
/// yet (a PLY whose faces come before its vertices) give the fan of the first corner; build_mesh
/// checks the triangles either way.
inline bool add_polygon(MeshRecords& records, const std::int64_t* corners, std::int64_t count, long line) {
  auto add = [&](std::int64_t a, std::int64_t b, std::int64_t c) {
    records.triangles.push_back({a, b, c});
    records.triangle_at.push_line(line);
  };
  const bool known = std::all_of(corners, corners + count, [&](std::int64_t c) {
    return c >= 0 && std::uint64_t(c) < records.points.size();
  });
  if (count == 3 || !known) {
    for (std::int64_t i = 1; i + 1 < count; ++i) add(corners[0], corners[i], corners[i + 1]);
    return true;
  }
  std::vector<Vec3> outline(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i) outline[std::size_t(i)] = records.points[std::size_t(corners[i])];
  const auto triangles = triangulate_polygon(outline);
  for (const auto& t : triangles) add(corners[t[0]], corners[t[1]], corners[t[2]]);
  return !triangles.empty();
}

}  // namespace bodyfit::io_detail
