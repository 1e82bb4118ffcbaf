#pragma once
// The Medit / GMF file format shared by the .mesh and the .sol files (io_medit.cpp, io_sol.cpp):
// keyword codes, the text and binary scanners over a whole file in memory (errors name the line or
// the byte) and the buffered writers.
//
// Text files are a sequence of keywords, each followed by its data; numbers and keywords are
// separated by any whitespace, '#' starts a comment. Binary files (libMeshb's GMF layout) start
// with the code word 1 (endianness) and the version, then each keyword is
//   int32 code, position of the next keyword (int32 for versions 1-2, int64 for 3-4),
//   [record count: int32 for versions 1-3, int64 for 4], [solution header], records.
// Version 1 stores reals as float, later versions as double; version 4 stores integers as int64.
#include "io_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>

namespace bodyfit::io_detail {

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

// ---------------------------------------------------------------------------------------------
// Text scanner: whitespace-separated tokens over the whole file in memory, with line numbers.

class TextScanner {
 public:
  TextScanner(std::string_view text, const std::filesystem::path& file, long first_line = 1)
      : p_(text.data()), end_(text.data() + text.size()), file_(file), line_(first_line) {}

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
  /// The text from here to the end.
  std::string_view rest() const { return {p_, remaining()}; }
  /// Continue at `position` (in the rest), which is on line `line`.
  void jump_to(const char* position, long line) {
    p_ = position;
    line_ = line;
  }

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

  /// The keyword of the next section, after skip_blank(). A number there is an error: the section
  /// before held more `records` than its count said.
  std::string_view keyword(const char* records) {
    if (!next_is_word()) {
      const std::string_view token = word();
      throw error(fmt::format("expected a keyword, found '{}' (more {} than the section's count?)", token.substr(0, 40),
                              records));
    }
    return word();
  }

  /// Skip the numbers of a section we do not read, up to the next keyword.
  void skip_numbers() {
    while (skip_blank() && !next_is_word()) word();
  }

  /// The number after MeshVersionFormatted: 1 to 4.
  int format_version() {
    const std::int64_t version = integer("the version number");
    if (version < 1 || version > 4)
      throw error(fmt::format("unsupported MeshVersionFormatted {} (expected 1 to 4)", version));
    return int(version);
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

  /// An integer that must fit an int (the refs of vertices, edges and faces).
  int reference(const char* what) {
    const std::int64_t value = integer(what);
    if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max())
      throw error(fmt::format("{} {} does not fit in 32 bits (refs are from {} to {})", what, value,
                              std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
    return int(value);
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
  const std::filesystem::path& file_;
  long line_ = 1;
  const char* section_ = nullptr;
  std::int64_t record_ = 0, count_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Binary scanner over the whole file in memory.

class BinaryScanner {
 public:
  BinaryScanner(std::string_view bytes, const std::filesystem::path& file) : bytes_(bytes), file_(file) {}

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
  const std::filesystem::path& file_;
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
BinaryFormat read_binary_header(BinaryScanner& in);

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

/// The record count of a binary keyword (int32 or int64 by version), non-negative.
std::int64_t read_count(BinaryScanner& in, const BinaryFormat& format, const char* section);
/// A Medit Dimension must be 2 or 3.
void check_dimension(int dimension, const std::function<InputError(const std::string&)>& error);
/// The value of a binary Dimension keyword that starts at `start`, checked.
int read_binary_dimension(BinaryScanner& in, std::size_t start);
/// Throws unless the file had its MeshVersionFormatted line (`what`: "mesh", "solution").
void require_version(bool versioned, const std::filesystem::path& file, const char* what);
/// Room for `count` records of at least `min_bytes` each, to reject absurd counts before allocating.
bool plausible_count(std::int64_t count, std::size_t remaining, std::size_t min_bytes);

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

/// The binary format for a file of about `estimated_bytes`: version 2, or 3 (64-bit positions) past 2 GB.
BinaryFormat binary_format_for(std::uint64_t estimated_bytes);

}  // namespace bodyfit::io_detail
