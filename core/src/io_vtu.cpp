// VTK XML UnstructuredGrid (.vtu, raw binary appended data, UInt64 block headers) and the
// ParaView collection (.pvd) that lists one .vtu per time.
#include "io_internal.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/geometry.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstring>

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
  for (auto v : mesh.vertices()) (void)v, ++n_points;
  for (auto f : mesh.faces()) (void)f, ++n_cells;
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
    for (auto v : mesh.vertices()) {
      double x = value_of(v);
      append_raw(b.bytes, &x, 1);
    }
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
  for (const auto& [name, values] : fields.point_vectors) {
    Block b{fmt::format(R"(type="Float64" Name="{}" NumberOfComponents="3")", xml_escape(name)), {}};
    b.bytes.reserve(24 * n_points);
    for (auto v : mesh.vertices()) append_raw(b.bytes, values[std::size_t(v.idx())].data(), 3);
    point_blocks.push_back(std::move(b));
  }
  // Cell data: region, quality, then the caller's fields.
  {
    Block region{R"(type="Int32" Name="region")", {}}, quality{R"(type="Float64" Name="quality")", {}};
    region.bytes.reserve(4 * n_cells);
    quality.bytes.reserve(8 * n_cells);
    for (auto f : mesh.faces()) {
      std::int32_t r = mesh.region(f);
      double q = face_quality(mesh, f);
      append_raw(region.bytes, &r, 1);
      append_raw(quality.bytes, &q, 1);
    }
    cell_blocks.push_back(std::move(region));
    cell_blocks.push_back(std::move(quality));
  }
  for (const auto& [name, values] : fields.cell_scalars) {
    Block b{fmt::format(R"(type="Float64" Name="{}")", xml_escape(name)), {}};
    b.bytes.reserve(8 * n_cells);
    for (auto f : mesh.faces()) append_raw(b.bytes, &values[std::size_t(f.idx())], 1);
    cell_blocks.push_back(std::move(b));
  }
  // Geometry: points, connectivity, offsets, types.
  {
    Block points{R"(type="Float64" Name="Points" NumberOfComponents="3")", {}};
    points.bytes.reserve(24 * n_points);
    for (auto v : mesh.vertices()) append_raw(points.bytes, mesh.point(v).data(), 3);
    Block connectivity{R"(type="Int64" Name="connectivity")", {}};
    Block offsets{R"(type="Int64" Name="offsets")", {}};
    Block types{R"(type="UInt8" Name="types")", {}};
    connectivity.bytes.reserve(24 * n_cells);
    offsets.bytes.reserve(8 * n_cells);
    std::int64_t offset = 0;
    for (auto f : mesh.faces()) {
      std::int64_t tri[3];
      int k = 0;
      for (auto v : mesh.fv_range(f)) tri[k++] = index[std::size_t(v.idx())];
      append_raw(connectivity.bytes, tri, 3);
      offset += 3;
      append_raw(offsets.bytes, &offset, 1);
    }
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
