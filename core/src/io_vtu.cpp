// VTK XML UnstructuredGrid (.vtu, raw binary appended data, UInt64 block headers) written and read
// back (with what ParaView writes uncompressed: base64, ASCII, UInt32 headers), and the ParaView
// collection (.pvd) that lists one .vtu per time.
#include "io_internal.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/geometry.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <map>

namespace bodyfit {
namespace {

namespace fs = std::filesystem;

std::string xml_escape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string xml_unescape(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '&') {
      out += text[i];
      continue;
    }
    static constexpr std::pair<std::string_view, char> kEntities[] = {
        {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
    bool matched = false;
    for (auto [entity, c] : kEntities)
      if (text.substr(i, entity.size()) == entity) {
        out += c;
        i += entity.size() - 1;
        matched = true;
        break;
      }
    if (!matched) out += '&';
  }
  return out;
}

/// One appended data block: its XML declaration and raw bytes.
struct Block {
  std::string declaration;  // DataArray attributes except offset
  std::string bytes;
};

template <class T>
void append_raw(std::string& bytes, const T* data, std::size_t count) {
  const auto* raw = reinterpret_cast<const char*>(data);
  bytes.append(raw, raw + count * sizeof(T));
}

}  // namespace

void write_vtu(const SurfaceMesh& mesh, const std::filesystem::path& file, const VtuFields& fields) {
  if (io_detail::extension_of(file) != ".vtu")
    throw file_error(file, fmt::format("write_vtu: expected a .vtu file name, got '{}'", io_detail::extension_of(file)));
  const auto index = io_detail::vertex_numbering(mesh);
  std::size_t n_points = 0, n_cells = 0;
  io_detail::for_each_vertex(mesh, [&](VertexHandle) { ++n_points; });
  io_detail::for_each_face(mesh, [&](FaceHandle) { ++n_cells; });
  const bool compact = n_points == mesh.n_vertices();

  auto check_size = [&](const std::string& name, std::size_t size, std::size_t expected, const char* what) {
    if (size != expected)
      throw file_error(file, fmt::format("field '{}' has {} values, expected one per {} ({})", name, size, what,
                                         expected));
  };
  for (const auto& [name, values] : fields.point_scalars) check_size(name, values.size(), mesh.n_vertices(), "vertex");
  for (const auto& [name, values] : fields.point_vectors) check_size(name, values.size(), mesh.n_vertices(), "vertex");
  for (const auto& [name, values] : fields.cell_scalars) check_size(name, values.size(), mesh.n_faces(), "face");

  std::vector<Block> point_blocks, cell_blocks, geometry_blocks;
  // Point data: phi, then the caller's fields (indexed by vertex idx, written for live vertices).
  auto point_scalar = [&](const std::string& name, auto value_of) {
    Block b{fmt::format(R"(type="Float64" Name="{}")", xml_escape(name)), {}};
    b.bytes.reserve(8 * n_points);
    io_detail::for_each_vertex(mesh, [&](VertexHandle v) {
      const double x = value_of(v);
      append_raw(b.bytes, &x, 1);
    });
    point_blocks.push_back(std::move(b));
  };
  point_scalar("phi", [&](VertexHandle v) { return mesh.phi(v); });
  for (const auto& field : fields.point_scalars) {
    const std::string& name = field.first;
    const ScalarField& values = field.second;  // a variable, not a binding: lambdas capture it (clang 14)
    if (compact) {
      Block b{fmt::format(R"(type="Float64" Name="{}")", xml_escape(name)), {}};
      append_raw(b.bytes, values.data(), values.size());
      point_blocks.push_back(std::move(b));
    } else {
      point_scalar(name, [&](VertexHandle v) { return values[std::size_t(v.idx())]; });
    }
  }
  for (const auto& field : fields.point_vectors) {
    const auto& values = field.second;  // a variable, not a binding: lambdas capture it (clang 14)
    Block b{fmt::format(R"(type="Float64" Name="{}" NumberOfComponents="3")", xml_escape(field.first)), {}};
    b.bytes.reserve(24 * n_points);
    io_detail::for_each_vertex(mesh, [&](VertexHandle v) { append_raw(b.bytes, values[std::size_t(v.idx())].data(), 3); });
    point_blocks.push_back(std::move(b));
  }
  // Cell data: region, quality, then the caller's fields.
  {
    Block region{R"(type="Int32" Name="region")", {}}, quality{R"(type="Float64" Name="quality")", {}};
    region.bytes.reserve(4 * n_cells);
    quality.bytes.reserve(8 * n_cells);
    io_detail::for_each_face(mesh, [&](FaceHandle f) {
      const std::int32_t r = mesh.region(f);
      const double q = face_quality(mesh, f);
      append_raw(region.bytes, &r, 1);
      append_raw(quality.bytes, &q, 1);
    });
    cell_blocks.push_back(std::move(region));
    cell_blocks.push_back(std::move(quality));
  }
  for (const auto& field : fields.cell_scalars) {
    const auto& values = field.second;  // a variable, not a binding: lambdas capture it (clang 14)
    Block b{fmt::format(R"(type="Float64" Name="{}")", xml_escape(field.first)), {}};
    b.bytes.reserve(8 * n_cells);
    io_detail::for_each_face(mesh, [&](FaceHandle f) { append_raw(b.bytes, &values[std::size_t(f.idx())], 1); });
    cell_blocks.push_back(std::move(b));
  }
  // Geometry: points, connectivity, offsets, types.
  {
    Block points{R"(type="Float64" Name="Points" NumberOfComponents="3")", {}};
    points.bytes.reserve(24 * n_points);
    io_detail::for_each_vertex(mesh, [&](VertexHandle v) { append_raw(points.bytes, mesh.point(v).data(), 3); });
    Block connectivity{R"(type="Int64" Name="connectivity")", {}};
    Block offsets{R"(type="Int64" Name="offsets")", {}};
    Block types{R"(type="UInt8" Name="types")", {}};
    connectivity.bytes.reserve(24 * n_cells);
    offsets.bytes.reserve(8 * n_cells);
    std::int64_t offset = 0;
    io_detail::for_each_face(mesh, [&](FaceHandle f) {
      std::int64_t tri[3];
      int k = 0;
      for (auto v : mesh.fv_range(f)) tri[k++] = index[std::size_t(v.idx())];
      append_raw(connectivity.bytes, tri, 3);
      offset += 3;
      append_raw(offsets.bytes, &offset, 1);
    });
    types.bytes.assign(n_cells, char(5));  // VTK_TRIANGLE
    geometry_blocks.push_back(std::move(points));
    geometry_blocks.push_back(std::move(connectivity));
    geometry_blocks.push_back(std::move(offsets));
    geometry_blocks.push_back(std::move(types));
  }

  write_atomically(file, [&](std::ostream& out) {
    std::uint64_t offset = 0;
    std::string xml;
    auto declare = [&](const std::vector<Block>& blocks, std::size_t first, std::size_t count, const char* indent) {
      for (std::size_t i = first; i < first + count; ++i) {
        xml += fmt::format("{}<DataArray {} format=\"appended\" offset=\"{}\"/>\n", indent, blocks[i].declaration,
                           offset);
        offset += 8 + blocks[i].bytes.size();
      }
    };
    xml += "<?xml version=\"1.0\"?>\n";
    xml += "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
    xml += "  <UnstructuredGrid>\n";
    xml += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", n_points, n_cells);
    xml += "      <PointData Scalars=\"phi\">\n";
    declare(point_blocks, 0, point_blocks.size(), "        ");
    xml += "      </PointData>\n      <CellData Scalars=\"region\">\n";
    declare(cell_blocks, 0, cell_blocks.size(), "        ");
    xml += "      </CellData>\n      <Points>\n";
    declare(geometry_blocks, 0, 1, "        ");
    xml += "      </Points>\n      <Cells>\n";
    declare(geometry_blocks, 1, 3, "        ");
    xml += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
    out.write(xml.data(), std::streamsize(xml.size()));
    for (const auto* blocks : {&point_blocks, &cell_blocks, &geometry_blocks})
      for (const auto& b : *blocks) {
        std::uint64_t size = b.bytes.size();
        out.write(reinterpret_cast<const char*>(&size), sizeof size);
        out.write(b.bytes.data(), std::streamsize(b.bytes.size()));
      }
    const std::string tail = "\n  </AppendedData>\n</VTKFile>\n";
    out.write(tail.data(), std::streamsize(tail.size()));
  });
}

namespace {

/// One <DataArray> of a VTU file.
struct DataArray {
  std::string name, type, format;
  int components = 1;
  std::uint64_t offset = 0;
  std::string_view inline_text;  ///< format="ascii" or "binary": the element's text
  long line = 0;
};

std::size_t type_size(const std::string& type) {
  if (type == "Float64" || type == "Int64" || type == "UInt64") return 8;
  if (type == "Float32" || type == "Int32" || type == "UInt32") return 4;
  if (type == "Int16" || type == "UInt16") return 2;
  if (type == "Int8" || type == "UInt8") return 1;
  return 0;
}

/// The value of `name="..."` in an element's text ("" when absent).
std::string attribute(std::string_view element, std::string_view name) {
  const std::string key = fmt::format(" {}=\"", name);
  const auto p = element.find(key);
  if (p == std::string_view::npos) return {};
  const auto start = p + key.size();
  const auto end = element.find('"', start);
  return end == std::string_view::npos ? std::string() : std::string(element.substr(start, end - start));
}

std::string base64_decode(std::string_view text, const fs::path& file, long line) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::string out;
  unsigned buffer = 0;
  int bits = 0;
  for (char c : text) {
    if (c == '=' || std::isspace(static_cast<unsigned char>(c))) continue;
    const int v = value(c);
    if (v < 0) throw file_error(file, line, fmt::format("'{}' is not a base64 character", c));
    buffer = (buffer << 6) | unsigned(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((buffer >> bits) & 0xffu);
    }
  }
  return out;
}

/// Reads the arrays of one VTU file: raw or base64 appended data, base64 inline data ("binary"),
/// or ASCII; the header of each binary block is UInt32 or UInt64 (header_type).
class VtuArrays {
 public:
  explicit VtuArrays(const fs::path& file) : file_(file), bytes_(io_detail::read_file_bytes(file)) {
    const std::string_view text(bytes_);
    const auto root = text.find("<VTKFile");
    if (root == std::string_view::npos) throw file_error(file, "not a VTK XML file: no <VTKFile> element");
    const std::string_view header = text.substr(root, text.find('>', root) - root);
    if (attribute(header, "type") != "UnstructuredGrid")
      throw file_error(file, fmt::format("a VTK file of type '{}': expected an UnstructuredGrid (.vtu)",
                                         attribute(header, "type")));
    if (const std::string order = attribute(header, "byte_order"); !order.empty() && order != "LittleEndian")
      throw file_error(file, fmt::format("byte order '{}': only LittleEndian files are read", order));
    if (!attribute(header, "compressor").empty())
      throw file_error(file, fmt::format("compressed data ({}): save it uncompressed (ParaView: Data Mode Appended, "
                                         "no compression)",
                                         attribute(header, "compressor")));
    header64_ = attribute(header, "header_type") != "UInt32";
    const auto appended = text.find("<AppendedData");
    if (appended != std::string_view::npos) {
      const std::string_view element = text.substr(appended, text.find('>', appended) - appended);
      raw_ = attribute(element, "encoding") == "raw";
      const auto underscore = text.find('_', appended + element.size());
      if (underscore == std::string_view::npos) throw file_error(file, "AppendedData without its '_' marker");
      data_start_ = underscore + 1;
    }
    const std::string_view markup = text.substr(0, appended == std::string_view::npos ? text.size() : appended);
    long line = 1;
    std::size_t counted = 0;
    std::string section;
    for (std::size_t pos = markup.find('<'); pos != std::string_view::npos; pos = markup.find('<', pos + 1)) {
      line += long(std::count(markup.begin() + long(counted), markup.begin() + long(pos), '\n'));
      counted = pos;
      const auto end = markup.find('>', pos);
      if (end == std::string_view::npos) throw file_error(file, line, "unterminated element");
      const std::string_view element = markup.substr(pos, end - pos);
      for (const char* name : {"PointData", "CellData", "Points", "Cells"})
        if (element.starts_with(std::string("<") + name)) section = name;
      if (!element.starts_with("<DataArray")) continue;
      DataArray a;
      a.name = attribute(element, "Name");
      a.type = attribute(element, "type");
      a.format = attribute(element, "format");
      a.line = line;
      if (const std::string n = attribute(element, "NumberOfComponents"); !n.empty()) a.components = std::atoi(n.c_str());
      if (type_size(a.type) == 0) throw file_error(file, line, fmt::format("DataArray of type '{}'", a.type));
      if (a.format == "appended") {
        if (!data_start_) throw file_error(file, line, "an appended DataArray, but no AppendedData");
        a.offset = std::strtoull(attribute(element, "offset").c_str(), nullptr, 10);
      } else if (!element.ends_with("/")) {
        // The values come first; VTK may follow them with <InformationKey> elements.
        const auto close = markup.find('<', end);
        if (close == std::string_view::npos) throw file_error(file, line, "DataArray without </DataArray>");
        a.inline_text = markup.substr(end + 1, close - end - 1);
      }
      arrays_[section].push_back(std::move(a));
    }
  }

  const std::vector<DataArray>& in(const std::string& section) const {
    static const std::vector<DataArray> none;
    auto it = arrays_.find(section);
    return it == arrays_.end() ? none : it->second;
  }
  const DataArray* find(const std::string& section, std::string_view name) const {
    for (const DataArray& a : in(section))
      if (a.name == name) return &a;
    return nullptr;
  }

  /// The array's values, converted to double, `expected` × its components of them.
  std::vector<double> values(const DataArray& a, std::size_t expected) const {
    const std::size_t count = expected * std::size_t(std::max(a.components, 1));
    if (count > bytes_.size())  // every value takes at least a byte
      throw file_error(file_, a.line, fmt::format("'{}': {} values, more than the file holds", a.name, count));
    std::vector<double> out;
    out.reserve(count);
    if (a.format == "ascii") {
      std::string text(a.inline_text);
      const char* p = text.c_str();
      char* end = nullptr;
      for (std::size_t i = 0; i < count; ++i, p = end) {
        const double v = std::strtod(p, &end);
        if (end == p) throw file_error(file_, a.line, fmt::format("'{}': expected {} numbers", a.name, count));
        out.push_back(v);
      }
      return out;
    }
    std::string decoded;
    std::string_view block;
    const std::size_t header = header64_ ? 8 : 4;
    if (a.format == "appended") {
      if (raw_) {
        if (data_start_ + a.offset + header > bytes_.size())
          throw file_error(file_, a.line, fmt::format("'{}': its block lies beyond the end of the file", a.name));
        block = std::string_view(bytes_).substr(data_start_ + a.offset);
      } else {
        const auto end = bytes_.find('<', data_start_);
        decoded = base64_decode(std::string_view(bytes_).substr(data_start_ + a.offset,
                                                                 (end == std::string::npos ? bytes_.size() : end) -
                                                                     data_start_ - a.offset),
                                file_, a.line);
        block = decoded;
      }
    } else {  // "binary": base64 of the header and the data
      decoded = base64_decode(a.inline_text, file_, a.line);
      block = decoded;
    }
    if (block.size() < header) throw file_error(file_, a.line, fmt::format("'{}': truncated block", a.name));
    std::uint64_t size = 0;
    std::memcpy(&size, block.data(), header);
    const std::size_t width = type_size(a.type);
    if (size != count * width || block.size() < header + size)
      throw file_error(file_, a.line, fmt::format("'{}': {} bytes of data, expected {} values of {} bytes", a.name,
                                                   size, count, width));
    const char* data = block.data() + header;
    for (std::size_t i = 0; i < count; ++i) out.push_back(decode(a.type, data + i * width));
    return out;
  }

 private:
  static double decode(const std::string& type, const char* at) {
    auto get = [&](auto value) {
      std::memcpy(&value, at, sizeof value);
      return double(value);
    };
    if (type == "Float64") return get(double());
    if (type == "Float32") return get(float());
    if (type == "Int64") return get(std::int64_t());
    if (type == "UInt64") return get(std::uint64_t());
    if (type == "Int32") return get(std::int32_t());
    if (type == "UInt32") return get(std::uint32_t());
    if (type == "Int16") return get(std::int16_t());
    if (type == "UInt16") return get(std::uint16_t());
    if (type == "Int8") return get(std::int8_t());
    return get(std::uint8_t());
  }

  fs::path file_;
  std::string bytes_;
  bool header64_ = true, raw_ = true;
  std::size_t data_start_ = 0;
  std::map<std::string, std::vector<DataArray>> arrays_;
};

}  // namespace

SurfaceMesh read_vtu(const std::filesystem::path& file, VtuFields* fields, const ReadOptions& options) {
  const VtuArrays arrays(file);
  const std::string bytes = io_detail::read_file_bytes(file);
  const auto piece = bytes.find("<Piece");
  if (piece == std::string::npos) throw file_error(file, "no <Piece> element");
  const std::string_view element = std::string_view(bytes).substr(piece, bytes.find('>', piece) - piece);
  const std::size_t n_points = std::strtoull(attribute(element, "NumberOfPoints").c_str(), nullptr, 10);
  const std::size_t n_cells = std::strtoull(attribute(element, "NumberOfCells").c_str(), nullptr, 10);
  if (bytes.find("<Piece", piece + 1) != std::string::npos) throw file_error(file, "several pieces: only one is read");
  const DataArray* points = arrays.in("Points").empty() ? nullptr : &arrays.in("Points").front();
  const DataArray* connectivity = arrays.find("Cells", "connectivity");
  const DataArray* offsets = arrays.find("Cells", "offsets");
  const DataArray* types = arrays.find("Cells", "types");
  if (!points || points->components != 3 || !connectivity || !offsets)
    throw file_error(file, "expected Points (3 components) and Cells (connectivity, offsets)");

  io_detail::MeshRecords r;
  r.vertex_at = r.triangle_at = io_detail::Locator::none();
  const std::vector<double> xyz = arrays.values(*points, n_points);
  r.points.resize(n_points);
  for (std::size_t i = 0; i < n_points; ++i) r.points[i] = Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  const std::vector<double> ends = arrays.values(*offsets, n_cells);
  const std::size_t corners = n_cells ? std::size_t(ends.back()) : 0;
  const std::vector<double> corner = arrays.values(*connectivity, corners);
  const std::vector<double> kinds = types ? arrays.values(*types, n_cells) : std::vector<double>();
  double start = 0;
  for (std::size_t c = 0; c < n_cells; ++c) {
    if ((!kinds.empty() && kinds[c] != 5) || ends[c] - start != 3)
      throw file_error(file, fmt::format("cell {} is not a triangle (VTK type {}, {} corners): a surface of triangles "
                                         "is read",
                                         c + 1, kinds.empty() ? 0.0 : kinds[c], ends[c] - start));
    const std::size_t at = std::size_t(start);
    r.triangles.push_back({std::int64_t(corner[at]), std::int64_t(corner[at + 1]), std::int64_t(corner[at + 2])});
    start = ends[c];
  }
  if (const DataArray* region = arrays.find("CellData", "region")) {
    for (double value : arrays.values(*region, n_cells)) r.triangle_refs.push_back(int(value));
  }
  SurfaceMesh mesh = io_detail::build_mesh(std::move(r), file, options);
  for (const DataArray& a : arrays.in("PointData")) {
    const std::vector<double> values = arrays.values(a, n_points);
    if (a.components == 1 && a.name == "phi") {
      io_detail::for_each_vertex(mesh, [&](VertexHandle v) { mesh.phi(v) = values[std::size_t(v.idx())]; });
    }
    if (!fields) continue;
    if (a.components == 1) {
      fields->point_scalars.emplace_back(a.name, values);
    } else if (a.components == 3) {
      VectorField vectors(n_points);
      for (std::size_t i = 0; i < n_points; ++i) vectors[i] = Vec3(values[3 * i], values[3 * i + 1], values[3 * i + 2]);
      fields->point_vectors.emplace_back(a.name, std::move(vectors));
    }
  }
  if (fields)
    for (const DataArray& a : arrays.in("CellData"))
      if (a.components == 1 && a.name != "region") fields->cell_scalars.emplace_back(a.name, arrays.values(a, n_cells));
  return mesh;
}

PvdWriter::PvdWriter(std::filesystem::path pvd_file) : file_(std::move(pvd_file)) {}

PvdWriter PvdWriter::resume(std::filesystem::path pvd_file, double max_time) {
  PvdWriter writer(pvd_file);
  if (!fs::exists(pvd_file)) return writer;
  const std::string text = io_detail::read_file_bytes(pvd_file);
  if (text.find("<Collection") == std::string::npos)
    throw file_error(pvd_file, "not a ParaView collection: no <Collection> element");
  long line = 1;
  std::size_t line_start = 0;
  auto attribute = [&](std::string_view element, std::string_view name, long at) {
    const std::string key = fmt::format(" {}=\"", name);
    auto p = element.find(key);
    if (p == std::string_view::npos) throw file_error(pvd_file, at, fmt::format("DataSet without a {} attribute", name));
    auto start = p + key.size();
    auto end = element.find('"', start);
    if (end == std::string_view::npos) throw file_error(pvd_file, at, fmt::format("unterminated {} attribute", name));
    return std::string(element.substr(start, end - start));
  };
  for (std::size_t pos = text.find("<DataSet"); pos != std::string::npos; pos = text.find("<DataSet", pos + 1)) {
    line += std::count(text.begin() + long(line_start), text.begin() + long(pos), '\n');
    line_start = pos;
    auto end = text.find('>', pos);
    if (end == std::string::npos) throw file_error(pvd_file, line, "unterminated DataSet element");
    std::string_view element(text.data() + pos, end - pos);
    const std::string time_text = attribute(element, "timestep", line);
    double time = 0;
    auto [ptr, ec] = std::from_chars(time_text.data(), time_text.data() + time_text.size(), time);
    if (ec != std::errc() || ptr != time_text.data() + time_text.size())
      throw file_error(pvd_file, line, fmt::format("malformed timestep '{}': expected a real number", time_text));
    if (time <= max_time) writer.entries_.emplace_back(time, xml_unescape(attribute(element, "file", line)));
  }
  writer.flush();
  return writer;
}

void PvdWriter::add(double time, const std::filesystem::path& dataset) {
  entries_.emplace_back(time, dataset.generic_string());
  flush();
}

void PvdWriter::flush() const {
  write_atomically(file_, [&](std::ostream& out) {
    std::string xml =
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        "  <Collection>\n";
    for (const auto& [time, name] : entries_)
      xml += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n", time, xml_escape(name));
    xml += "  </Collection>\n</VTKFile>\n";
    out.write(xml.data(), std::streamsize(xml.size()));
  });
}

}  // namespace bodyfit
