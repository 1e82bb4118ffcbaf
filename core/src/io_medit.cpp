// Medit / GMF files: .mesh (text), .meshb (binary), .sol (text), .solb (binary).
//
// Text files are a sequence of keywords, each followed by its data; numbers and keywords are
// separated by any whitespace, '#' starts a comment. Binary files (libMeshb's GMF layout) start
// with the code word 1 (endianness) and the version, then each keyword is
//   int32 code, position of the next keyword (int32 for versions 1-2, int64 for 3-4),
//   [record count: int32 for versions 1-3, int64 for 4], [solution header], records.
// Version 1 stores reals as float, later versions as double; version 4 stores integers as int64.
#include "io_internal.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/guards.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string_view>

namespace bodyfit::io_detail {
namespace {

namespace fs = std::filesystem;

// GMF keyword codes (libMeshb's table).
enum Keyword : int {
  kVersion = 1,
  kDimension = 3,
  kVertices = 4,
  kEdges = 5,
  kTriangles = 6,
  kQuadrilaterals = 7,
  kTetrahedra = 8,
  kPrisms = 9,
  kHexahedra = 10,
  kCorners = 13,
  kRidges = 14,
  kRequiredVertices = 15,
  kRequiredEdges = 16,
  kRequiredTriangles = 17,
  kRequiredQuadrilaterals = 18,
  kTangentAtEdgeVertices = 19,
  kNormalAtVertices = 20,
  kNormalAtTriangleVertices = 21,
  kEnd = 54,
  kTangents = 59,
  kNormals = 60,
  kTangentAtVertices = 61,
  kSolAtVertices = 62,
};

/// Layout of the records of the text keywords we read or skip: integers and reals per record
/// (reals_per_dim counts reals repeated `dimension` times, as in Vertices or Normals).
struct TextLayout {
  std::string_view name;
  int code;
  int integers;
  int reals_per_dim;
};
constexpr TextLayout kTextLayouts[] = {
    {"Vertices", kVertices, 1, 1},
    {"Edges", kEdges, 3, 0},
    {"Triangles", kTriangles, 4, 0},
    {"Quadrilaterals", kQuadrilaterals, 5, 0},
    {"Tetrahedra", kTetrahedra, 5, 0},
    {"Prisms", kPrisms, 7, 0},
    {"Hexahedra", kHexahedra, 9, 0},
    {"Corners", kCorners, 1, 0},
    {"Ridges", kRidges, 1, 0},
    {"RequiredVertices", kRequiredVertices, 1, 0},
    {"RequiredEdges", kRequiredEdges, 1, 0},
    {"RequiredTriangles", kRequiredTriangles, 1, 0},
    {"RequiredQuadrilaterals", kRequiredQuadrilaterals, 1, 0},
    {"TangentAtEdgeVertices", kTangentAtEdgeVertices, 3, 0},
    {"NormalAtVertices", kNormalAtVertices, 2, 0},
    {"NormalAtTriangleVertices", kNormalAtTriangleVertices, 3, 0},
    {"Tangents", kTangents, 0, 1},
    {"Normals", kNormals, 0, 1},
    {"TangentAtVertices", kTangentAtVertices, 2, 0},
};

const TextLayout* find_layout(std::string_view word) {
  for (const auto& l : kTextLayouts)
    if (l.name == word) return &l;
  return nullptr;
}

/// Number of reals per vertex of a solution type (1 scalar, 2 vector, 3 symmetric, 4 full matrix).
int solution_size(int type, int dimension) {
  switch (type) {
    case 1: return 1;
    case 2: return dimension;
    case 3: return dimension * (dimension + 1) / 2;
    case 4: return dimension * dimension;
    default: return 0;
  }
}

// ---------------------------------------------------------------------------------------------
// Text scanner: whitespace-separated tokens over the whole file in memory, with line numbers.

class TextScanner {
 public:
  TextScanner(std::string_view text, const fs::path& file)
      : p_(text.data()), end_(text.data() + text.size()), file_(file) {}

  /// Skip whitespace and comments; true when a token follows.
  bool skip_blank() {
    while (p_ < end_) {
      char c = *p_;
      if (c == '\n') {
        ++line_;
        ++p_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++p_;
      } else if (c == '#') {
        while (p_ < end_ && *p_ != '\n') ++p_;
      } else {
        return true;
      }
    }
    return false;
  }
  long line() const { return line_; }
  std::size_t remaining() const { return std::size_t(end_ - p_); }

  std::string_view word() {
    if (!skip_blank()) return {};
    const char* start = p_;
    while (p_ < end_ && !is_space(*p_)) ++p_;
    return {start, std::size_t(p_ - start)};
  }

  /// Skip a "quoted string" (Identifier, Geometry); a bare word is skipped too.
  void skip_string() {
    if (!skip_blank()) return;
    if (*p_ == '"') {
      ++p_;
      while (p_ < end_ && *p_ != '"') {
        if (*p_ == '\n') ++line_;
        ++p_;
      }
      if (p_ < end_) ++p_;
    } else {
      word();
    }
  }

  /// Peek: does the next token start with a letter (a keyword)?
  bool next_is_word() {
    return skip_blank() && ((*p_ >= 'A' && *p_ <= 'Z') || (*p_ >= 'a' && *p_ <= 'z'));
  }

  std::int64_t integer(const char* what) {
    if (!skip_blank()) throw eof(what);
    const char* start = p_;
    if (*p_ == '+') ++p_;
    std::int64_t value = 0;
    auto [ptr, ec] = std::from_chars(p_, end_, value);
    if (ec != std::errc() || (ptr < end_ && !is_space(*ptr))) throw malformed(start, what, "an integer");
    p_ = ptr;
    return value;
  }

  double real(const char* what) {
    if (!skip_blank()) throw eof(what);
    const char* start = p_;
    if (*p_ == '+') ++p_;
    double value = 0;
    auto [ptr, ec] = std::from_chars(p_, end_, value);
    if (ec == std::errc::result_out_of_range) {
      // Subnormal or huge values: strtod gives the correctly rounded result (0, ±HUGE_VAL).
      value = std::strtod(std::string(p_, ptr).c_str(), nullptr);
      ec = std::errc();
    }
    if (ec != std::errc() || (ptr < end_ && !is_space(*ptr))) throw malformed(start, what, "a real number");
    p_ = ptr;
    return value;
  }

  InputError error(const std::string& what) const { return file_error(file_, line_, what); }

  /// Describe the record being read, for error messages; set cheaply by the section loops.
  void set_context(const char* section, std::int64_t record, std::int64_t count) {
    section_ = section;
    record_ = record;
    count_ = count;
  }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
  std::string context() const {
    if (!section_) return {};
    return fmt::format(" in {} (record {} of {})", section_, record_ + 1, count_);
  }
  InputError eof(const char* what) const {
    return error(fmt::format("unexpected end of file{}: expected {}", context(), what));
  }
  InputError malformed(const char* start, const char* what, const char* kind) const {
    const char* stop = start;
    while (stop < end_ && !is_space(*stop) && stop - start < 40) ++stop;
    return error(
        fmt::format("malformed number '{}'{}: expected {} ({})", std::string_view(start, std::size_t(stop - start)),
                    context(), what, kind));
  }

  const char* p_;
  const char* end_;
  const fs::path& file_;
  long line_ = 1;
  const char* section_ = nullptr;
  std::int64_t record_ = 0, count_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Binary scanner over the whole file in memory.

class BinaryScanner {
 public:
  BinaryScanner(std::string_view bytes, const fs::path& file) : bytes_(bytes), file_(file) {}

  std::size_t pos() const { return pos_; }
  void seek(std::size_t pos) { pos_ = pos; }
  std::size_t size() const { return bytes_.size(); }
  void set_swap(bool swap) { swap_ = swap; }

  InputError error(std::size_t at, const std::string& what) const {
    return file_error(file_, fmt::format("byte {}: {}", at, what));
  }
  std::size_t left() const { return bytes_.size() - std::min(pos_, bytes_.size()); }
  /// Check that n more bytes exist.
  void need(std::size_t n, const std::string& what) const {
    if (n > left())
      throw error(pos_, fmt::format("unexpected end of file: expected {} ({} bytes, {} left)", what, n, left()));
  }
  /// Check that `count` records of `size` bytes exist, without computing count·size (a corrupt
  /// 64-bit count would overflow it).
  void need_records(std::uint64_t count, std::size_t size, const std::string& what) const {
    if (count > left() / size)
      throw error(pos_, fmt::format("unexpected end of file: expected {} ({} x {} bytes, {} left)", what, count, size,
                                    left()));
  }

  template <class T>
  T get(const char* what) {
    need(sizeof(T), what);
    return get_unchecked<T>();
  }
  template <class T>
  T get_unchecked() {
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    if (swap_) value = byteswapped(value);
    return value;
  }

 private:
  template <class T>
  static T byteswapped(T value) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }

  std::string_view bytes_;
  const fs::path& file_;
  std::size_t pos_ = 0;
  bool swap_ = false;
};

/// The format of a binary file's records, from its version.
struct BinaryFormat {
  int version = 2;
  bool float32() const { return version == 1; }
  bool int64_positions() const { return version >= 3; }
  bool int64_integers() const { return version >= 4; }
  std::size_t real_size() const { return float32() ? 4 : 8; }
  std::size_t int_size() const { return int64_integers() ? 8 : 4; }
};

/// Read the version header of a binary file and set the byte order.
BinaryFormat read_binary_header(BinaryScanner& in) {
  auto code = in.get<std::int32_t>("the code word 1");
  if (code != 1) {
    if (code == 0x01000000) {
      in.set_swap(true);
    } else {
      throw in.error(0, fmt::format("bad code word {} (expected 1 in either byte order): not a GMF binary file", code));
    }
  }
  BinaryFormat format;
  format.version = in.get<std::int32_t>("the version");
  if (format.version < 1 || format.version > 4)
    throw in.error(4, fmt::format("unsupported version {} (expected 1 to 4)", format.version));
  return format;
}

/// Walk the keywords of a binary file, calling visit(code, scanner, keyword start) for each one,
/// positioned just after the next-keyword position. Stops at End or at a zero next position.
template <class Visit>
void walk_binary_keywords(BinaryScanner& in, const BinaryFormat& format, Visit&& visit) {
  std::size_t pos = in.pos();
  for (;;) {
    in.seek(pos);
    if (pos == in.size()) return;  // a file without End
    const std::size_t start = pos;
    auto code = in.get<std::int32_t>("a keyword code");
    if (code == kEnd) return;
    std::uint64_t next = format.int64_positions() ? std::uint64_t(in.get<std::int64_t>("the next keyword position"))
                                                  : std::uint64_t(std::uint32_t(in.get<std::int32_t>(
                                                        "the next keyword position")));
    if (next > in.size())
      throw in.error(start, fmt::format("truncated file: keyword {} says the next keyword is at byte {}, but the file "
                                        "has {} bytes",
                                        code, next, in.size()));
    if (next != 0 && next <= start)
      throw in.error(start, fmt::format("keyword {}: the next keyword position {} is not after this keyword", code,
                                        next));
    visit(code, start);
    if (next == 0) return;
    pos = std::size_t(next);
  }
}

std::int64_t read_count(BinaryScanner& in, const BinaryFormat& format, const char* section) {
  const std::size_t at = in.pos();
  std::int64_t n = format.int64_integers() ? in.get<std::int64_t>("a record count")
                                           : std::int64_t(in.get<std::int32_t>("a record count"));
  if (n < 0) throw in.error(at, fmt::format("negative record count {} for {}", n, section));
  return n;
}

// ---------------------------------------------------------------------------------------------
// Mesh reading.

struct MeshHeader {
  int version = 0;
  int dimension = 3;
};

void check_dimension(int dimension, const std::function<InputError(const std::string&)>& error) {
  if (dimension != 2 && dimension != 3) throw error(fmt::format("unsupported Dimension {} (expected 2 or 3)", dimension));
}

/// A file's 1-based index, 0-based. The smallest int64 stays as it is (an index out of range for the
/// builder to report) instead of overflowing.
std::int64_t zero_based(std::int64_t index) {
  return index == std::numeric_limits<std::int64_t>::min() ? index : index - 1;
}

/// Room for `count` records of at least `min_bytes` each, to reject absurd counts before allocating.
bool plausible_count(std::int64_t count, std::size_t remaining, std::size_t min_bytes) {
  return count >= 0 && std::uint64_t(count) <= remaining / min_bytes + 1;
}

MeshRecords read_medit_text(std::string_view text, const fs::path& file) {
  TextScanner in(text, file);
  MeshRecords r;
  MeshHeader header;
  bool ended = false;
  auto count_of = [&](const char* section) {
    auto n = in.integer(fmt::format("the number of {}", section).c_str());
    if (!plausible_count(n, in.remaining(), 2))
      throw in.error(fmt::format("record count {} of {} does not fit in the rest of the file", n, section));
    return n;
  };
  // What to reserve for n records of k numbers: a record takes at least 2k characters (a digit
  // and a separator each), so a count larger than the file allows (an error further on, when the
  // records run out) does not allocate more than the file could hold.
  auto room = [&](std::int64_t n, int k) {
    return std::min(std::size_t(n), in.remaining() / (2 * std::size_t(k)) + 1);
  };
  auto index_list = [&](const char* section, BulkVector<std::int64_t>& items, Locator& at) {
    auto n = count_of(section);
    items.reserve(items.size() + room(n, 1));
    for (std::int64_t i = 0; i < n; ++i) {
      in.set_context(section, i, n);
      in.skip_blank();
      at.push_line(in.line());
      items.push_back(zero_based(in.integer("an index")));
    }
    in.set_context(nullptr, 0, 0);
  };
  while (!ended) {
    if (!in.skip_blank()) break;
    const long keyword_line = in.line();
    if (!in.next_is_word()) {
      auto token = in.word();
      throw file_error(file, keyword_line,
                       fmt::format("expected a keyword, found '{}' (more records than the section's count?)",
                                   token.substr(0, 40)));
    }
    auto word = in.word();
    if (word == "MeshVersionFormatted") {
      header.version = int(in.integer("the version number"));
      if (header.version < 1 || header.version > 4)
        throw in.error(fmt::format("unsupported MeshVersionFormatted {} (expected 1 to 4)", header.version));
    } else if (word == "Dimension") {
      header.dimension = int(in.integer("the dimension"));
      check_dimension(header.dimension, [&](const std::string& w) { return in.error(w); });
    } else if (word == "Vertices") {
      auto n = count_of("Vertices");
      r.points.reserve(room(n, header.dimension + 1));
      r.vertex_refs.reserve(room(n, header.dimension + 1));
      r.vertex_at.reserve(room(n, header.dimension + 1));
      for (std::int64_t i = 0; i < n; ++i) {
        in.set_context("Vertices", i, n);
        in.skip_blank();
        r.vertex_at.push_line(in.line());
        Vec3 p(0, 0, 0);
        p[0] = in.real("the x coordinate");
        p[1] = in.real("the y coordinate");
        if (header.dimension == 3) p[2] = in.real("the z coordinate");
        r.points.push_back(p);
        r.vertex_refs.push_back(int(in.integer("the vertex ref")));
      }
    } else if (word == "Triangles") {
      auto n = count_of("Triangles");
      r.triangles.reserve(room(n, 4));
      r.triangle_refs.reserve(room(n, 4));
      r.triangle_at.reserve(room(n, 4));
      for (std::int64_t i = 0; i < n; ++i) {
        in.set_context("Triangles", i, n);
        in.skip_blank();
        r.triangle_at.push_line(in.line());
        std::array<std::int64_t, 3> t{};
        for (auto& v : t) v = zero_based(in.integer("a vertex index"));
        r.triangles.push_back(t);
        r.triangle_refs.push_back(int(in.integer("the triangle ref")));
      }
    } else if (word == "Edges") {
      auto n = count_of("Edges");
      r.edges.reserve(room(n, 3));
      r.edge_refs.reserve(room(n, 3));
      for (std::int64_t i = 0; i < n; ++i) {
        in.set_context("Edges", i, n);
        in.skip_blank();
        r.edge_at.push_line(in.line());
        std::array<std::int64_t, 2> e{};
        for (auto& v : e) v = zero_based(in.integer("a vertex index"));
        r.edges.push_back(e);
        r.edge_refs.push_back(int(in.integer("the edge ref")));
      }
    } else if (word == "Corners") {
      index_list("Corners", r.corners, r.corner_at);
    } else if (word == "RequiredVertices") {
      index_list("RequiredVertices", r.required_vertices, r.required_vertex_at);
    } else if (word == "Ridges") {
      index_list("Ridges", r.ridges, r.ridge_at);
    } else if (word == "RequiredEdges") {
      index_list("RequiredEdges", r.required_edges, r.required_edge_at);
    } else if (word == "End") {
      ended = true;
    } else if (word == "Identifier" || word == "Geometry") {
      in.skip_string();
    } else if (const TextLayout* layout = find_layout(word)) {
      // A known section we do not use: skip its records by their layout.
      const std::string name(word);
      auto n = count_of(name.c_str());
      for (std::int64_t i = 0; i < n; ++i) {
        in.set_context(name.c_str(), i, n);
        for (int k = 0; k < layout->reals_per_dim * header.dimension; ++k) in.real("a real number");
        for (int k = 0; k < layout->integers; ++k) in.integer("an integer");
      }
      in.set_context(nullptr, 0, 0);
    } else {
      // Unknown keyword: skip its numbers up to the next keyword.
      while (in.skip_blank() && !in.next_is_word()) in.word();
    }
    in.set_context(nullptr, 0, 0);
  }
  if (header.version == 0) throw file_error(file, 1, "missing MeshVersionFormatted: not a Medit mesh file");
  return r;
}

MeshRecords read_medit_binary(std::string_view bytes, const fs::path& file) {
  BinaryScanner in(bytes, file);
  const BinaryFormat format = read_binary_header(in);
  MeshRecords r;
  int dimension = 3;
  auto read_index = [&]() -> std::int64_t {
    return format.int64_integers() ? in.get_unchecked<std::int64_t>() : std::int64_t(in.get_unchecked<std::int32_t>());
  };
  auto read_real = [&]() -> double {
    return format.float32() ? double(in.get_unchecked<float>()) : in.get_unchecked<double>();
  };
  auto records = [&](const char* section, std::size_t record_size) {
    auto n = read_count(in, format, section);
    in.need_records(std::uint64_t(n), record_size, fmt::format("{} records of {}", n, section));
    return n;
  };
  auto index_list = [&](const char* section, BulkVector<std::int64_t>& items, Locator& at) {
    auto n = records(section, format.int_size());
    at = Locator::bytes(in.pos(), format.int_size());
    for (std::int64_t i = 0; i < n; ++i) items.push_back(zero_based(read_index()));
  };
  walk_binary_keywords(in, format, [&](int code, std::size_t start) {
    switch (code) {
      case kDimension:
        dimension = in.get<std::int32_t>("the dimension");
        check_dimension(dimension, [&](const std::string& w) { return in.error(start, w); });
        break;
      case kVertices: {
        const std::size_t size = std::size_t(dimension) * format.real_size() + format.int_size();
        auto n = records("Vertices", size);
        r.vertex_at = Locator::bytes(in.pos(), size);
        r.points.resize(std::size_t(n));
        r.vertex_refs.resize(std::size_t(n));
        for (std::int64_t i = 0; i < n; ++i) {
          Vec3 p(0, 0, 0);
          for (int k = 0; k < dimension; ++k) p[k] = read_real();
          r.points[std::size_t(i)] = p;
          r.vertex_refs[std::size_t(i)] = int(read_index());
        }
        break;
      }
      case kTriangles: {
        const std::size_t size = 4 * format.int_size();
        auto n = records("Triangles", size);
        r.triangle_at = Locator::bytes(in.pos(), size);
        r.triangles.resize(std::size_t(n));
        r.triangle_refs.resize(std::size_t(n));
        for (std::int64_t i = 0; i < n; ++i) {
          auto& t = r.triangles[std::size_t(i)];
          for (auto& v : t) v = zero_based(read_index());
          r.triangle_refs[std::size_t(i)] = int(read_index());
        }
        break;
      }
      case kEdges: {
        const std::size_t size = 3 * format.int_size();
        auto n = records("Edges", size);
        r.edge_at = Locator::bytes(in.pos(), size);
        r.edges.resize(std::size_t(n));
        r.edge_refs.resize(std::size_t(n));
        for (std::int64_t i = 0; i < n; ++i) {
          auto& e = r.edges[std::size_t(i)];
          for (auto& v : e) v = zero_based(read_index());
          r.edge_refs[std::size_t(i)] = int(read_index());
        }
        break;
      }
      case kCorners: index_list("Corners", r.corners, r.corner_at); break;
      case kRequiredVertices: index_list("RequiredVertices", r.required_vertices, r.required_vertex_at); break;
      case kRidges: index_list("Ridges", r.ridges, r.ridge_at); break;
      case kRequiredEdges: index_list("RequiredEdges", r.required_edges, r.required_edge_at); break;
      default: break;  // other keywords are skipped through their next-keyword position
    }
  });
  return r;
}

// ---------------------------------------------------------------------------------------------
// Writing.

/// Buffered output to the stream of write_atomically: numbers are formatted with std::to_chars
/// (shortest round-trip form for doubles, so a text round trip is bit-exact) or copied as bytes
/// straight into a block handed to the stream when full. One check per value: the block has
/// room for the longest value past its nominal size.
class OutputBuffer {
 public:
  explicit OutputBuffer(std::ostream& out)
      : out_(out), data_(std::make_unique_for_overwrite<char[]>(kBlock + kSlack)), p_(data_.get()) {}
  void real(double x) {
    make_room();
    p_ = std::to_chars(p_, p_ + kSlack, x).ptr;
  }
  void integer(std::int64_t i) {
    make_room();
    p_ = std::to_chars(p_, p_ + kSlack, i).ptr;
  }
  void put(char c) {
    make_room();
    *p_++ = c;
  }
  void text(std::string_view s) {
    for (char c : s) put(c);
  }
  template <class T>
  void binary(T value) {
    make_room();
    std::memcpy(p_, &value, sizeof(T));
    p_ += sizeof(T);
  }
  void flush() {
    out_.write(data_.get(), std::streamsize(p_ - data_.get()));
    p_ = data_.get();
  }

 private:
  static constexpr std::ptrdiff_t kBlock = 1 << 20;
  static constexpr std::ptrdiff_t kSlack = 64;  // > the longest double (24 characters) or int64 (20)
  void make_room() {
    if (p_ - data_.get() >= kBlock) flush();
  }
  std::ostream& out_;
  std::unique_ptr<char[]> data_;
  char* p_;
};

/// What a Medit writer writes: vertices, triangles, and the edges MMG must keep.
struct MeditContent {
  std::vector<std::int64_t> vertex_index;  // by vertex idx, -1 for deleted
  std::vector<VertexHandle> vertices;
  std::vector<FaceHandle> faces;
  std::vector<EdgeHandle> edges;  // interface, ridge, required, non-zero ref or boundary
  std::vector<std::int64_t> corners, required_vertices, ridges, required_edges;  // 1-based
};

MeditContent collect(const SurfaceMesh& mesh) {
  MeditContent c;
  c.vertex_index = vertex_numbering(mesh);
  c.vertices.reserve(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    c.vertices.push_back(v);
    const auto number = c.vertex_index[v.idx()] + 1;
    if (mesh.corner(v)) c.corners.push_back(number);
    if (mesh.required(v)) c.required_vertices.push_back(number);
  }
  c.faces.reserve(mesh.n_faces());
  for (auto f : mesh.faces()) c.faces.push_back(f);
  for (auto e : mesh.edges()) {
    if (!(mesh.interface(e) || mesh.ridge(e) || mesh.required(e) || mesh.edge_ref(e) != 0 || mesh.is_boundary(e)))
      continue;
    c.edges.push_back(e);
    const auto number = std::int64_t(c.edges.size());
    if (mesh.ridge(e)) c.ridges.push_back(number);
    if (mesh.required(e)) c.required_edges.push_back(number);
  }
  return c;
}

int written_edge_ref(const SurfaceMesh& mesh, EdgeHandle e) {
  return mesh.interface(e) ? kInterfaceRef : mesh.edge_ref(e);
}

void write_medit_text(const SurfaceMesh& mesh, const MeditContent& c, std::ostream& stream) {
  OutputBuffer out(stream);
  out.text("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n");
  out.integer(std::int64_t(c.vertices.size()));
  out.put('\n');
  for (auto v : c.vertices) {
    const auto& p = mesh.point(v);
    out.real(p[0]), out.put(' '), out.real(p[1]), out.put(' '), out.real(p[2]), out.put(' ');
    out.integer(mesh.vertex_ref(v)), out.put('\n');
  }
  out.text("\nTriangles\n");
  out.integer(std::int64_t(c.faces.size()));
  out.put('\n');
  for (auto f : c.faces) {
    auto h = mesh.halfedge_handle(f);
    auto v0 = mesh.to_vertex_handle(h);
    h = mesh.next_halfedge_handle(h);
    auto v1 = mesh.to_vertex_handle(h);
    auto v2 = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
    for (auto v : {v0, v1, v2}) out.integer(c.vertex_index[v.idx()] + 1), out.put(' ');
    out.integer(mesh.region(f)), out.put('\n');
  }
  if (!c.edges.empty()) {
    out.text("\nEdges\n");
    out.integer(std::int64_t(c.edges.size()));
    out.put('\n');
    for (auto e : c.edges) {
      auto h = mesh.halfedge_handle(e, 0);
      out.integer(c.vertex_index[mesh.from_vertex_handle(h).idx()] + 1), out.put(' ');
      out.integer(c.vertex_index[mesh.to_vertex_handle(h).idx()] + 1), out.put(' ');
      out.integer(written_edge_ref(mesh, e)), out.put('\n');
    }
  }
  auto list = [&](const char* name, const std::vector<std::int64_t>& items) {
    if (items.empty()) return;
    out.put('\n'), out.text(name), out.put('\n');
    out.integer(std::int64_t(items.size())), out.put('\n');
    for (auto i : items) out.integer(i), out.put('\n');
  };
  list("Ridges", c.ridges);
  list("RequiredEdges", c.required_edges);
  list("Corners", c.corners);
  list("RequiredVertices", c.required_vertices);
  out.text("\nEnd\n");
  out.flush();
}

/// Binary keyword writer: each keyword's next position is known from its record count and size.
class BinaryKeywordWriter {
 public:
  BinaryKeywordWriter(OutputBuffer& out, const BinaryFormat& format) : out_(out), format_(format) {
    out_.binary<std::int32_t>(1);
    out_.binary<std::int32_t>(format.version);
    offset_ = 8;
  }
  /// Header of keyword `code` whose remaining bytes (after the position) total `payload`.
  void begin(int code, std::uint64_t payload) {
    const std::uint64_t position_size = format_.int64_positions() ? 8 : 4;
    const std::uint64_t next = code == kEnd ? 0 : offset_ + 4 + position_size + payload;
    out_.binary<std::int32_t>(code);
    if (format_.int64_positions())
      out_.binary<std::int64_t>(std::int64_t(next));
    else
      out_.binary<std::int32_t>(std::int32_t(next));
    offset_ = next;
  }
  void count(std::int64_t n) {
    if (format_.int64_integers())
      out_.binary<std::int64_t>(n);
    else
      out_.binary<std::int32_t>(std::int32_t(n));
  }
  std::uint64_t count_size() const { return format_.int_size(); }
  void integer(std::int64_t i) { count(i); }
  void real(double x) { out_.binary<double>(x); }

 private:
  OutputBuffer& out_;
  BinaryFormat format_;
  std::uint64_t offset_ = 0;
};

BinaryFormat binary_format_for(std::uint64_t estimated_bytes) {
  BinaryFormat format;
  format.version = estimated_bytes < (1ull << 31) - 1024 ? 2 : 3;  // 64-bit positions past 2 GB
  return format;
}

void write_medit_binary(const SurfaceMesh& mesh, const MeditContent& c, std::ostream& stream) {
  const std::uint64_t estimate = c.vertices.size() * 28 + c.faces.size() * 16 + c.edges.size() * 12 + 4096;
  const BinaryFormat format = binary_format_for(estimate);
  OutputBuffer out(stream);
  BinaryKeywordWriter w(out, format);
  const std::uint64_t is = format.int_size();
  w.begin(kDimension, 4);
  out.binary<std::int32_t>(3);
  w.begin(kVertices, is + c.vertices.size() * (24 + is));
  w.count(std::int64_t(c.vertices.size()));
  for (auto v : c.vertices) {
    const auto& p = mesh.point(v);
    w.real(p[0]);
    w.real(p[1]);
    w.real(p[2]);
    w.integer(mesh.vertex_ref(v));
  }
  w.begin(kTriangles, is + c.faces.size() * 4 * is);
  w.count(std::int64_t(c.faces.size()));
  for (auto f : c.faces) {
    for (auto v : mesh.fv_range(f)) w.integer(c.vertex_index[v.idx()] + 1);
    w.integer(mesh.region(f));
  }
  if (!c.edges.empty()) {
    w.begin(kEdges, is + c.edges.size() * 3 * is);
    w.count(std::int64_t(c.edges.size()));
    for (auto e : c.edges) {
      auto h = mesh.halfedge_handle(e, 0);
      w.integer(c.vertex_index[mesh.from_vertex_handle(h).idx()] + 1);
      w.integer(c.vertex_index[mesh.to_vertex_handle(h).idx()] + 1);
      w.integer(written_edge_ref(mesh, e));
    }
  }
  auto list = [&](int code, const std::vector<std::int64_t>& items) {
    if (items.empty()) return;
    w.begin(code, is + items.size() * is);
    w.count(std::int64_t(items.size()));
    for (auto i : items) w.integer(i);
  };
  list(kRidges, c.ridges);
  list(kRequiredEdges, c.required_edges);
  list(kCorners, c.corners);
  list(kRequiredVertices, c.required_vertices);
  w.begin(kEnd, 0);
  out.flush();
}

// ---------------------------------------------------------------------------------------------
// Solutions.

struct SolRead {
  std::vector<SolField> fields;
  long line = 0;            // text: line of the SolAtVertices keyword
  std::size_t offset = 0;   // binary: byte offset of the keyword
  bool found = false;
};

std::vector<SolField> make_fields(const std::vector<int>& types, int dimension, std::int64_t n,
                                  const std::function<InputError(const std::string&)>& error) {
  std::vector<SolField> fields;
  for (int t : types) {
    int size = solution_size(t, dimension);
    if (size == 0) throw error(fmt::format("unknown solution type {} (expected 1 scalar, 2 vector, 3 or 4 matrix)", t));
    SolField f;
    f.dimension = size;
    f.values.reserve(std::size_t(n) * std::size_t(size));
    fields.push_back(std::move(f));
  }
  return fields;
}

SolRead read_sol_text(std::string_view text, const fs::path& file) {
  TextScanner in(text, file);
  SolRead result;
  int dimension = 3;
  bool versioned = false;
  while (in.skip_blank()) {
    const long keyword_line = in.line();
    if (!in.next_is_word()) {
      auto token = in.word();
      throw file_error(file, keyword_line,
                       fmt::format("expected a keyword, found '{}' (more values than the section's count?)",
                                   token.substr(0, 40)));
    }
    auto word = in.word();
    if (word == "MeshVersionFormatted") {
      int version = int(in.integer("the version number"));
      if (version < 1 || version > 4)
        throw in.error(fmt::format("unsupported MeshVersionFormatted {} (expected 1 to 4)", version));
      versioned = true;
    } else if (word == "Dimension") {
      dimension = int(in.integer("the dimension"));
      check_dimension(dimension, [&](const std::string& w) { return in.error(w); });
    } else if (word == "SolAtVertices" && !result.found) {
      result.found = true;
      result.line = keyword_line;
      auto n = in.integer("the number of vertices");
      if (!plausible_count(n, in.remaining(), 2))
        throw in.error(fmt::format("vertex count {} of SolAtVertices does not fit in the rest of the file", n));
      auto ntypes = in.integer("the number of solution fields");
      if (ntypes < 1 || ntypes > 64) throw in.error(fmt::format("bad number of solution fields {} (expected 1 to 64)", ntypes));
      std::vector<int> types;
      for (std::int64_t k = 0; k < ntypes; ++k) types.push_back(int(in.integer("a solution type")));
      result.fields = make_fields(types, dimension, n, [&](const std::string& w) { return in.error(w); });
      for (std::int64_t i = 0; i < n; ++i) {
        in.set_context("SolAtVertices", i, n);
        for (auto& f : result.fields)
          for (int k = 0; k < f.dimension; ++k) f.values.push_back(in.real("a solution value"));
      }
      in.set_context(nullptr, 0, 0);
    } else if (word == "End") {
      break;
    } else {
      while (in.skip_blank() && !in.next_is_word()) in.word();
    }
  }
  if (!versioned) throw file_error(file, 1, "missing MeshVersionFormatted: not a Medit solution file");
  return result;
}

SolRead read_sol_binary(std::string_view bytes, const fs::path& file) {
  BinaryScanner in(bytes, file);
  const BinaryFormat format = read_binary_header(in);
  SolRead result;
  int dimension = 3;
  walk_binary_keywords(in, format, [&](int code, std::size_t start) {
    if (code == kDimension) {
      dimension = in.get<std::int32_t>("the dimension");
      check_dimension(dimension, [&](const std::string& w) { return in.error(start, w); });
    } else if (code == kSolAtVertices && !result.found) {
      result.found = true;
      result.offset = start;
      auto n = read_count(in, format, "SolAtVertices");
      const std::size_t types_at = in.pos();
      auto ntypes = in.get<std::int32_t>("the number of solution fields");
      if (ntypes < 1 || ntypes > 64)
        throw in.error(types_at, fmt::format("bad number of solution fields {} (expected 1 to 64)", ntypes));
      std::vector<int> types;
      for (int k = 0; k < ntypes; ++k) types.push_back(in.get<std::int32_t>("a solution type"));
      auto fields = make_fields(types, dimension, 0, [&](const std::string& w) { return in.error(types_at, w); });
      std::size_t per_vertex = 0;
      for (auto& f : fields) per_vertex += std::size_t(f.dimension);
      in.need_records(std::uint64_t(n), per_vertex * format.real_size(),
                      fmt::format("{} vertices of {} solution values", n, per_vertex));
      for (auto& f : fields) f.values.reserve(std::size_t(n) * std::size_t(f.dimension));
      for (std::int64_t i = 0; i < n; ++i)
        for (auto& f : fields)
          for (int k = 0; k < f.dimension; ++k)
            f.values.push_back(format.float32() ? double(in.get_unchecked<float>()) : in.get_unchecked<double>());
      result.fields = std::move(fields);
    }
  });
  return result;
}

int solution_type_of(int components, const fs::path& file) {
  for (int t = 1; t <= 4; ++t)
    if (solution_size(t, 3) == components) return t;
  throw file_error(file, fmt::format("cannot write a field with {} components (expected 1, 3, 6 or 9)", components));
}

}  // namespace

MeshRecords parse_medit(std::string_view bytes, const fs::path& file) {
  return extension_of(file) == ".meshb" ? read_medit_binary(bytes, file) : read_medit_text(bytes, file);
}

SurfaceMesh read_medit(const fs::path& file, const ReadOptions& options) {
  const FileBytes bytes(file);
  return build_mesh(parse_medit(bytes.view(), file), file, options);
}

void write_medit(const SurfaceMesh& mesh, const fs::path& file, bool binary) {
  const MeditContent content = collect(mesh);
  write_atomically(file, [&](std::ostream& out) {
    if (binary)
      write_medit_binary(mesh, content, out);
    else
      write_medit_text(mesh, content, out);
  });
}

}  // namespace bodyfit::io_detail

namespace bodyfit {

using io_detail::extension_of;

std::vector<SolField> read_sol_all(const std::filesystem::path& file, std::size_t expected_vertices) {
  const std::string ext = extension_of(file);
  if (ext != ".sol" && ext != ".solb")
    throw file_error(file, fmt::format("unknown solution extension '{}' (expected .sol or .solb)", ext));
  const io_detail::FileBytes bytes(file);
  const bool binary = ext == ".solb";
  auto result = binary ? io_detail::read_sol_binary(bytes.view(), file) : io_detail::read_sol_text(bytes.view(), file);
  auto where = [&](const std::string& what) {
    return binary ? file_error(file, fmt::format("byte {}: {}", result.offset, what))
                  : file_error(file, result.line, what);
  };
  if (!result.found) throw file_error(file, "no SolAtVertices section: expected a field at the vertices");
  const std::size_t n = result.fields.empty() ? 0 : result.fields.front().size();
  if (expected_vertices != 0 && n != expected_vertices)
    throw where(fmt::format("SolAtVertices has {} values per field, but the mesh has {} vertices", n,
                            expected_vertices));
  for (std::size_t k = 0; k < result.fields.size(); ++k) {
    const SolField& f = result.fields[k];
    if (const std::size_t i = find_non_finite(f.values); i < f.values.size())
      throw file_error(file, fmt::format("SolAtVertices: field {}, vertex {} has the value {} (every value must be "
                                         "finite)",
                                         k + 1, i / std::size_t(f.dimension) + 1, f.values[i]));
  }
  return std::move(result.fields);
}

SolField read_sol(const std::filesystem::path& file, std::size_t expected_vertices) {
  return std::move(read_sol_all(file, expected_vertices).front());
}

void write_sol(const std::filesystem::path& file, const std::vector<SolField>& fields) {
  const std::string ext = extension_of(file);
  if (ext != ".sol" && ext != ".solb")
    throw file_error(file, fmt::format("unknown solution extension '{}' (expected .sol or .solb)", ext));
  if (fields.empty()) throw file_error(file, "no field to write");
  const std::size_t n = fields.front().size();
  std::vector<int> types;
  for (const auto& f : fields) {
    if (f.dimension < 1 || f.values.size() != n * std::size_t(f.dimension))
      throw file_error(file, fmt::format("field '{}' has {} values, expected {} x {}", f.name, f.values.size(), n,
                                         f.dimension));
    types.push_back(io_detail::solution_type_of(f.dimension, file));
  }
  write_atomically(file, [&](std::ostream& stream) {
    io_detail::OutputBuffer out(stream);
    if (ext == ".sol") {
      out.text("MeshVersionFormatted 2\n\nDimension 3\n\nSolAtVertices\n");
      out.integer(std::int64_t(n)), out.put('\n');
      out.integer(std::int64_t(fields.size()));
      for (int t : types) out.put(' '), out.integer(t);
      out.put('\n');
      for (std::size_t i = 0; i < n; ++i) {
        bool first = true;
        for (const auto& f : fields)
          for (int k = 0; k < f.dimension; ++k) {
            if (!first) out.put(' ');
            out.real(f.values[i * std::size_t(f.dimension) + std::size_t(k)]);
            first = false;
          }
        out.put('\n');
      }
      out.text("\nEnd\n");
    } else {
      std::uint64_t per_vertex = 0;
      for (const auto& f : fields) per_vertex += std::uint64_t(f.dimension);
      const auto format = io_detail::binary_format_for(n * per_vertex * 8 + 1024);
      io_detail::BinaryKeywordWriter w(out, format);
      w.begin(io_detail::kDimension, 4);
      out.binary<std::int32_t>(3);
      w.begin(io_detail::kSolAtVertices, w.count_size() + 4 + 4 * fields.size() + n * per_vertex * 8);
      w.count(std::int64_t(n));
      out.binary<std::int32_t>(std::int32_t(fields.size()));
      for (int t : types) out.binary<std::int32_t>(t);
      for (std::size_t i = 0; i < n; ++i) {
        for (const auto& f : fields)
          for (int k = 0; k < f.dimension; ++k) w.real(f.values[i * std::size_t(f.dimension) + std::size_t(k)]);
      }
      w.begin(io_detail::kEnd, 0);
    }
    out.flush();
  });
}

ScalarField read_scalar_sol(const std::filesystem::path& file, std::size_t expected_vertices) {
  auto field = read_sol(file, expected_vertices);
  if (field.dimension != 1)
    throw file_error(file, fmt::format("expected a scalar field (type 1), found {} components per vertex",
                                       field.dimension));
  return std::move(field.values);
}

VectorField read_vector_sol(const std::filesystem::path& file, std::size_t expected_vertices) {
  auto field = read_sol(file, expected_vertices);
  if (field.dimension != 3 && field.dimension != 2)
    throw file_error(file, fmt::format("expected a vector field (type 2), found {} components per vertex",
                                       field.dimension));
  VectorField values(field.size(), Vec3(0, 0, 0));
  for (std::size_t i = 0; i < values.size(); ++i)
    for (int k = 0; k < field.dimension; ++k) values[i][k] = field.values[i * std::size_t(field.dimension) + std::size_t(k)];
  return values;
}

void write_scalar_sol(const std::filesystem::path& file, const ScalarField& values) {
  write_sol(file, {SolField{"", 1, values}});
}

void write_vector_sol(const std::filesystem::path& file, const VectorField& values) {
  SolField field{"", 3, {}};
  field.values.reserve(values.size() * 3);
  for (const auto& v : values) field.values.insert(field.values.end(), {v[0], v[1], v[2]});
  write_sol(file, {field});
}

}  // namespace bodyfit
