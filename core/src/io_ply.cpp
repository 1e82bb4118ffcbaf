// PLY (Stanford polygon format), read by bodyfit itself into the validated builder: OpenMesh's
// reader crashed on a property before any element, looped on a misspelt header line and on a
// malformed face list (tests/fuzz/regressions/openmesh-ply-*). The header is read line by line
// into elements and their properties; the body, ASCII or binary in either byte order, is read
// element by element with every read bounded by the file's end. The `vertex` element gives x, y, z
// (any scalar type), the `face` element its `vertex_indices` (or `vertex_index`) list; every other
// property and element is skipped by its size. The declared counts must fit in the file's length
// before anything is allocated.
#include "io_text.hpp"

#include <fmt/format.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace bodyfit::io_detail {
namespace {

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct ScalarName {
  std::string_view name;
  Scalar type;
};
constexpr std::array<ScalarName, 16> kScalarNames{{{"char", Scalar::Int8},     {"int8", Scalar::Int8},
                                                   {"uchar", Scalar::UInt8},   {"uint8", Scalar::UInt8},
                                                   {"short", Scalar::Int16},   {"int16", Scalar::Int16},
                                                   {"ushort", Scalar::UInt16}, {"uint16", Scalar::UInt16},
                                                   {"int", Scalar::Int32},     {"int32", Scalar::Int32},
                                                   {"uint", Scalar::UInt32},   {"uint32", Scalar::UInt32},
                                                   {"float", Scalar::Float32}, {"float32", Scalar::Float32},
                                                   {"double", Scalar::Float64}, {"float64", Scalar::Float64}}};

std::size_t size_of(Scalar type) {
  switch (type) {
    case Scalar::Int8:
    case Scalar::UInt8: return 1;
    case Scalar::Int16:
    case Scalar::UInt16: return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32: return 4;
    case Scalar::Float64: return 8;
  }
  return 0;
}

bool integral(Scalar type) { return type != Scalar::Float32 && type != Scalar::Float64; }

/// What the reader does with a property's values.
enum class Role { Skip, X, Y, Z, Corners };

struct Property {
  std::string name;
  bool list = false;
  Scalar count_type = Scalar::UInt8;  ///< lists only
  Scalar type = Scalar::Float32;      ///< the value's (a list's items')
  Role role = Role::Skip;
  long line = 0;
};

struct Element {
  std::string name;
  std::int64_t count = 0;
  std::vector<Property> properties;
  long line = 0;
  /// Bytes of one instance at least: its scalars and its lists' counts (binary), or two
  /// characters per property (ASCII: a digit and a separator).
  double min_bytes(bool ascii) const {
    double bytes = 0;
    for (const auto& p : properties) bytes += ascii ? 2.0 : double(size_of(p.list ? p.count_type : p.type));
    return bytes;
  }
};

enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::size_t body = 0;  ///< the byte after end_header's line
  long body_line = 0;    ///< the line number before the body's first line
};

std::string_view shown(std::string_view word) { return word.substr(0, 40); }

Header parse_header(std::string_view bytes, const std::filesystem::path& file) {
  Header header;
  long number = 0;
  for (std::size_t at = 0; at < bytes.size();) {
    const std::size_t end = std::min(bytes.find('\n', at), bytes.size());
    std::string_view line = bytes.substr(at, end - at);
    at = end + 1;
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    auto fail = [&](const std::string& what) { throw file_error(file, number, "PLY header: " + what); };
    Words words(line);
    const std::string_view first = words.next();
    if (number == 1) {
      if (line != "ply") throw file_error(file, 1, "not a PLY file: the first line must be 'ply'");
      continue;
    }
    if (number == 2) {
      const std::string_view format = words.next();
      if (first != "format" || words.next() != "1.0" || !words.next().empty())
        fail("the second line must be 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (format == "ascii") header.format = Format::Ascii;
      else if (format == "binary_little_endian") header.format = Format::BinaryLittleEndian;
      else if (format == "binary_big_endian") header.format = Format::BinaryBigEndian;
      else fail(fmt::format("unknown format '{}' (expected ascii, binary_little_endian or binary_big_endian)", shown(format)));
      continue;
    }
    if (first == "comment" || first == "obj_info" || first.empty()) continue;
    if (first == "end_header") {
      if (!words.next().empty()) fail("'end_header' must be alone on its line");
      header.body = std::min(at, bytes.size());
      header.body_line = number;
      return header;
    }
    if (first == "element") {
      Element element;
      element.name = std::string(words.next());
      const std::string_view count = words.next();
      if (element.name.empty() || !parse_number(count, element.count) || element.count < 0 || !words.next().empty())
        fail("expected 'element <name> <count>' with a non-negative integer count");
      for (const auto& other : header.elements)
        if (other.name == element.name) fail(fmt::format("a second element '{}'", shown(element.name)));
      element.line = number;
      header.elements.push_back(std::move(element));
      continue;
    }
    if (first == "property") {
      if (header.elements.empty()) fail("a 'property' before any 'element'");
      auto scalar = [&](std::string_view word) {
        for (const auto& [name, type] : kScalarNames)
          if (word == name) return type;
        fail(fmt::format("'{}' is not a PLY type (char, uchar, short, ushort, int, uint, float, double, or int8 to "
                         "float64)",
                         shown(word)));
        return Scalar::Int8;  // (not reached)
      };
      Property property;
      property.line = number;
      std::string_view type = words.next();
      if (type == "list") {
        property.list = true;
        property.count_type = scalar(words.next());
        if (!integral(property.count_type)) fail("a list's count type must be an integer type");
        type = words.next();
      }
      property.type = scalar(type);
      property.name = std::string(words.next());
      if (property.name.empty() || !words.next().empty())
        fail("expected 'property <type> <name>' or 'property list <count type> <item type> <name>'");
      for (const auto& other : header.elements.back().properties)
        if (other.name == property.name) fail(fmt::format("a second property '{}'", shown(property.name)));
      header.elements.back().properties.push_back(std::move(property));
      continue;
    }
    fail(fmt::format("'{}' is not a header keyword (element, property, comment, obj_info, end_header)", shown(first)));
  }
  throw file_error(file, number, number < 1 ? "not a PLY file: it is empty" : "PLY header: no 'end_header' line");
}

/// Where the reader is, for its messages: the element, the instance and the property.
struct Place {
  const Element* element = nullptr;
  std::int64_t instance = 0;
  const Property* property = nullptr;
  std::string describe() const {
    return fmt::format("{} {} (property '{}')", shown(element->name), instance + 1, shown(property->name));
  }
};

/// The body of an ASCII PLY file: numbers separated by blanks and newlines.
class AsciiBody {
 public:
  AsciiBody(std::string_view bytes, std::size_t start, long line, const std::filesystem::path& file)
      : bytes_(bytes), at_(start), line_(line + 1), file_(file) {}

  double real(const Place& place) {
    const std::string_view w = word(place);
    double value = 0;
    if (!parse_number(w, value))
      throw file_error(file_, line_, fmt::format("{}: '{}' is not a number", place.describe(), shown(w)));
    return value;
  }
  std::int64_t integer(Scalar, const Place& place) {
    const std::string_view w = word(place);
    std::int64_t value = 0;
    if (!parse_number(w, value))
      throw file_error(file_, line_, fmt::format("{}: '{}' is not an integer", place.describe(), shown(w)));
    return value;
  }
  /// The line of the next value (blank lines and line ends skipped first).
  long line() {
    skip_blanks();
    return line_;
  }
  /// Whether `count` values of `type` can still be in the file (each takes at least two bytes,
  /// the last one one).
  bool can_hold(std::int64_t count, Scalar) const { return count <= std::int64_t((bytes_.size() - at_) / 2 + 1); }
  void skip(std::int64_t count, Scalar, const Place& place) {
    for (std::int64_t i = 0; i < count; ++i) real(place);
  }
  std::string location() const { return fmt::format("line {}", line_); }
  long error_line() const { return line_; }

 private:
  void skip_blanks() {
    while (at_ < bytes_.size() && (is_blank(bytes_[at_]) || bytes_[at_] == '\n')) {
      if (bytes_[at_] == '\n') ++line_;
      ++at_;
    }
  }
  std::string_view word(const Place& place) {
    skip_blanks();
    const std::size_t start = at_;
    while (at_ < bytes_.size() && !is_blank(bytes_[at_]) && bytes_[at_] != '\n') ++at_;
    if (at_ == start)
      throw file_error(file_, line_, fmt::format("the file ends within {} of {} (truncated?)", place.describe(),
                                                 place.element->count));
    return bytes_.substr(start, at_ - start);
  }

  std::string_view bytes_;
  std::size_t at_;
  long line_;
  const std::filesystem::path& file_;
};

/// The body of a binary PLY file: fixed-size values in the header's byte order.
class BinaryBody {
 public:
  BinaryBody(std::string_view bytes, std::size_t start, bool big_endian, const std::filesystem::path& file)
      : bytes_(bytes), at_(start), swap_(big_endian != (std::endian::native == std::endian::big)), file_(file) {}

  double real(Scalar type, const Place& place) {
    switch (type) {
      case Scalar::Float32: return take<float>(place);
      case Scalar::Float64: return take<double>(place);
      default: return double(integer(type, place));
    }
  }
  std::int64_t integer(Scalar type, const Place& place) {
    switch (type) {
      case Scalar::Int8: return take<std::int8_t>(place);
      case Scalar::UInt8: return take<std::uint8_t>(place);
      case Scalar::Int16: return take<std::int16_t>(place);
      case Scalar::UInt16: return take<std::uint16_t>(place);
      case Scalar::Int32: return take<std::int32_t>(place);
      case Scalar::UInt32: return take<std::uint32_t>(place);
      default: break;
    }
    throw file_error(file_, fmt::format("byte {}: {}: expected an integer type", at_, place.describe()));
  }
  bool can_hold(std::int64_t count, Scalar type) const {
    return count >= 0 && double(count) * double(size_of(type)) <= double(bytes_.size() - at_);
  }
  void skip(std::int64_t count, Scalar type, const Place& place) {
    if (!can_hold(count, type)) throw ends(place);
    at_ += std::size_t(count) * size_of(type);
  }
  std::size_t offset() const { return at_; }

 private:
  InputError ends(const Place& place) const {
    return file_error(file_, fmt::format("byte {}: the file ends within {} of {} (truncated?)", at_, place.describe(),
                                         place.element->count));
  }
  template <class T>
  T take(const Place& place) {
    if (bytes_.size() - at_ < sizeof(T)) throw ends(place);
    using Bits = std::conditional_t<sizeof(T) == 1, std::uint8_t,
                                    std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                                       std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
    Bits bits;
    std::memcpy(&bits, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    if (swap_) {
      if constexpr (sizeof(T) == 2) bits = __builtin_bswap16(bits);
      else if constexpr (sizeof(T) == 4) bits = __builtin_bswap32(bits);
      else if constexpr (sizeof(T) == 8) bits = __builtin_bswap64(bits);
    }
    return std::bit_cast<T>(bits);
  }

  std::string_view bytes_;
  std::size_t at_;
  bool swap_;
  const std::filesystem::path& file_;
};

/// The roles of the vertex and face properties; InputError when x, y, z or the index list is
/// missing or of the wrong kind.
void assign_roles(Header& header, const std::filesystem::path& file) {
  for (auto& element : header.elements) {
    if (element.name == "vertex") {
      bool found[3] = {false, false, false};
      for (auto& p : element.properties) {
        const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
        if (axis < 0) continue;
        if (p.list) throw file_error(file, p.line, fmt::format("PLY header: the vertex property '{}' is a list", p.name));
        p.role = Role(int(Role::X) + axis);
        found[axis] = true;
      }
      if (!found[0] || !found[1] || !found[2])
        throw file_error(file, element.line, "PLY header: the vertex element needs the properties x, y and z");
      if (element.count > INT32_MAX)
        throw file_error(file, element.line, fmt::format("PLY header: {} vertices (at most 2^31 - 1)", element.count));
    } else if (element.name == "face") {
      Property* corners = nullptr;
      for (auto& p : element.properties)
        if (p.name == "vertex_indices" || p.name == "vertex_index") {
          if (corners) throw file_error(file, p.line, "PLY header: both vertex_indices and vertex_index");
          corners = &p;
        }
      if (!corners)
        throw file_error(file, element.line,
                         "PLY header: the face element needs a list property vertex_indices (or vertex_index)");
      if (!corners->list || !integral(corners->type))
        throw file_error(file, corners->line,
                         fmt::format("PLY header: '{}' must be a list of an integer type", corners->name));
      corners->role = Role::Corners;
      if (element.count > INT32_MAX)
        throw file_error(file, element.line, fmt::format("PLY header: {} faces (at most 2^31 - 1)", element.count));
    }
  }
}

/// Read every element of the body with `body` (AsciiBody or BinaryBody) into `records`.
template <class Body>
void read_body(Body& body, const Header& header, std::int64_t vertices, MeshRecords& records,
               const std::filesystem::path& file) {
  constexpr bool ascii = std::is_same_v<Body, AsciiBody>;
  std::vector<std::int64_t> corners;
  for (const Element& element : header.elements) {
    if (element.properties.empty()) continue;  // nothing to read, however many instances
    const bool is_vertex = element.name == "vertex";
    Place place{&element, 0, nullptr};
    for (std::int64_t i = 0; i < element.count; ++i) {
      place.instance = i;
      long line = 0;
      if constexpr (ascii) line = body.line();
      double xyz[3] = {0, 0, 0};
      for (const Property& p : element.properties) {
        place.property = &p;
        if (p.list) {
          std::size_t list_at = 0;  // (binary: the byte of the list's count, for messages)
          if constexpr (!ascii) list_at = body.offset();
          const std::int64_t count = body.integer(p.count_type, place);
          if (p.role != Role::Corners) {
            if (count < 0 || !body.can_hold(count, p.type))
              throw ascii ? file_error(file, line, fmt::format("{}: a list of {} items", place.describe(), count))
                          : file_error(file, fmt::format("byte {}: {}: a list of {} items, more than the rest of the "
                                                         "file holds",
                                                         list_at, place.describe(), count));
            body.skip(count, p.type, place);
            continue;
          }
          auto fail = [&](const std::string& what) -> InputError {
            if constexpr (ascii) return file_error(file, line, fmt::format("face {}: {}", i + 1, what));
            else return file_error(file, fmt::format("byte {}: face {}: {}", list_at, i + 1, what));
          };
          if (count < 3) throw fail(fmt::format("{} corners, expected at least 3", count));
          if (!body.can_hold(count, p.type))
            throw fail(fmt::format("{} corners, more than the rest of the file holds (truncated?)", count));
          corners.resize(std::size_t(count));
          for (auto& c : corners) {
            c = body.integer(p.type, place);
            if (c < 0 || c >= vertices)
              throw fail(fmt::format("corner {} is not a vertex index (0 to {})", c, vertices - 1));
          }
          if (!add_polygon(records, corners.data(), count, line))
            throw fail(fmt::format("a polygon of {} corners whose outline crosses itself or has no area cannot be triangulated", count));
        } else if (p.role == Role::Skip) {
          body.skip(1, p.type, place);
        } else {
          if constexpr (ascii) xyz[int(p.role) - int(Role::X)] = body.real(place);
          else xyz[int(p.role) - int(Role::X)] = body.real(p.type, place);
        }
      }
      if (is_vertex) {
        records.points.push_back(Vec3(xyz[0], xyz[1], xyz[2]));
        records.vertex_at.push_line(line);
      }
    }
  }
}

}  // namespace

MeshRecords parse_ply(std::string_view bytes, const std::filesystem::path& file) {
  Header header = parse_header(bytes, file);
  assign_roles(header, file);
  const bool ascii = header.format == Format::Ascii;
  std::int64_t vertices = 0, faces = 0;
  double needed = 0;
  for (const auto& element : header.elements) {
    needed += double(element.count) * element.min_bytes(ascii);
    if (element.name == "vertex") vertices = element.count;
    if (element.name == "face") faces = element.count;
  }
  const std::size_t body_size = bytes.size() - header.body;
  if (needed > double(body_size) + 1)
    throw file_error(file, fmt::format("the header declares {} vertices and {} faces ({} elements in all), which need "
                                       "at least {:.0f} bytes; the file has {} after its header (truncated or not "
                                       "this format?)",
                                       vertices, faces, header.elements.size(), needed, body_size));
  MeshRecords records;
  records.points.reserve(std::size_t(vertices));
  records.triangles.reserve(std::size_t(faces));
  if (ascii) {
    records.vertex_at = records.triangle_at = Locator::lines();
    records.vertex_at.reserve(std::size_t(vertices));
    records.triangle_at.reserve(std::size_t(faces));
    AsciiBody body(bytes, header.body, header.body_line, file);
    read_body(body, header, vertices, records, file);
  } else {
    // Vertices are located by byte when their records have a fixed size and come first.
    records.vertex_at = records.triangle_at = Locator::none();
    if (!header.elements.empty() && header.elements.front().name == "vertex") {
      const Element& first = header.elements.front();
      bool fixed = true;
      for (const auto& p : first.properties) fixed = fixed && !p.list;
      if (fixed) records.vertex_at = Locator::bytes(header.body, std::uint64_t(first.min_bytes(false)));
    }
    BinaryBody body(bytes, header.body, header.format == Format::BinaryBigEndian, file);
    read_body(body, header, vertices, records, file);
  }
  return records;
}

SurfaceMesh read_ply(const std::filesystem::path& file, const ReadOptions& options) {
  const FileBytes bytes(file);
  return build_mesh(parse_ply(bytes.view(), file), file, options);
}

}  // namespace bodyfit::io_detail
