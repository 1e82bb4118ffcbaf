// Medit / GMF meshes: .mesh (text) and .meshb (binary), read into MeshRecords and written from a
// SurfaceMesh with the edges MMG must keep. The format itself is in medit_format.hpp.
#include "medit_format.hpp"
#include "text_records.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/guards.hpp>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <limits>
#include <string_view>

namespace bodyfit::io_detail {
namespace {

namespace fs = std::filesystem;

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

struct MeshHeader {
  int version = 0;
  int dimension = 3;
};

/// A file's 1-based index, 0-based. The smallest int64 stays as it is (an index out of range for the
/// builder to report) instead of overflowing.
std::int64_t zero_based(std::int64_t index) {
  return index == std::numeric_limits<std::int64_t>::min() ? index : index - 1;
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
  // A section of records, each some `numbers` and a ref, appended to `items` and `refs`:
  // `record(scanner, i)` reads item i. By every thread when they are one per line.
  auto read_section = [&](const char* section, int numbers, auto& items, BulkVector<int>& refs, Locator& lines,
                          auto&& record) {
    const std::int64_t n = count_of(section);
    const std::size_t at = items.size();
    // Sized at once only for as many records as the rest of the file can hold (as `room`): a count
    // beyond is an error the loop below reports.
    if (n >= kParallelRecords && std::size_t(n) <= in.remaining() / (2 * std::size_t(numbers))) {
      const long first_line = (in.skip_blank(), in.line());
      items.resize(at + std::size_t(n));
      refs.resize(at + std::size_t(n));
      if (read_lines_in_parallel(in, n, file,
                                 [&](TextScanner& scanner, std::int64_t i) { record(scanner, at + std::size_t(i)); })) {
        lines.push_lines(first_line, std::size_t(n));
        return;
      }
      items.resize(at);
      refs.resize(at);
    }
    items.reserve(at + room(n, numbers));
    refs.reserve(at + room(n, numbers));
    lines.reserve(at + room(n, numbers));
    for (std::int64_t i = 0; i < n; ++i) {
      in.set_context(section, i, n);
      in.skip_blank();
      lines.push_line(in.line());
      items.emplace_back();
      refs.emplace_back();
      record(in, at + std::size_t(i));
    }
  };
  while (!ended) {
    if (!in.skip_blank()) break;
    const std::string_view word = in.keyword("records");
    if (word == "MeshVersionFormatted") {
      header.version = in.format_version();
    } else if (word == "Dimension") {
      header.dimension = int(in.integer("the dimension"));
      check_dimension(header.dimension, [&](const std::string& w) { return in.error(w); });
    } else if (word == "Vertices") {
      read_section("Vertices", header.dimension + 1, r.points, r.vertex_refs, r.vertex_at,
                   [&](TextScanner& scanner, std::size_t i) {
                     Vec3& p = r.points[i];
                     p[0] = scanner.real("the x coordinate");
                     p[1] = scanner.real("the y coordinate");
                     p[2] = header.dimension == 3 ? scanner.real("the z coordinate") : 0.0;
                     r.vertex_refs[i] = scanner.reference("the vertex ref");
                   });
    } else if (word == "Triangles") {
      read_section("Triangles", 4, r.triangles, r.triangle_refs, r.triangle_at, [&](TextScanner& scanner, std::size_t i) {
        for (auto& v : r.triangles[i]) v = zero_based(scanner.integer("a vertex index"));
        r.triangle_refs[i] = scanner.reference("the triangle ref");
      });
    } else if (word == "Edges") {
      read_section("Edges", 3, r.edges, r.edge_refs, r.edge_at, [&](TextScanner& scanner, std::size_t i) {
        for (auto& v : r.edges[i]) v = zero_based(scanner.integer("a vertex index"));
        r.edge_refs[i] = scanner.reference("the edge ref");
      });
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
      in.skip_numbers();  // an unknown keyword
    }
    in.set_context(nullptr, 0, 0);
  }
  require_version(header.version != 0, file, "mesh");
  return r;
}

/// Records [0, n) of `size` bytes each from `in`'s position, on both threads:
/// read(scanner at record `begin`, begin, end) by chunks of records. The first record that throws
/// throws, as a loop would; `in` is left after the last record.
template <class Read>
void read_records(BinaryScanner& in, std::int64_t n, std::size_t size, Read&& read) {
  constexpr std::int64_t kChunk = 16384;
  const std::size_t start = in.pos();
  const std::int64_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::exception_ptr> failed(std::size_t(chunks), nullptr);
  tbb::parallel_for(std::int64_t(0), chunks, [&](std::int64_t c) {
    BinaryScanner at = in;
    at.seek(start + std::size_t(c * kChunk) * size);
    try {
      read(at, c * kChunk, std::min(n, (c + 1) * kChunk));
    } catch (...) {
      failed[std::size_t(c)] = std::current_exception();
    }
  });
  for (const auto& error : failed)
    if (error) std::rethrow_exception(error);
  in.seek(start + std::size_t(n) * size);
}

MeshRecords read_medit_binary(std::string_view bytes, const fs::path& file) {
  BinaryScanner in(bytes, file);
  const BinaryFormat format = read_binary_header(in);
  MeshRecords r;
  int dimension = 3;
  auto read_index = [&](BinaryScanner& at) -> std::int64_t {
    return format.int64_integers() ? at.get_unchecked<std::int64_t>() : std::int64_t(at.get_unchecked<std::int32_t>());
  };
  // A ref of a 64-bit file must still fit an int.
  auto read_ref = [&](BinaryScanner& at, const char* what) -> int {
    const std::int64_t value = read_index(at);
    if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max())
      throw file_error(file, fmt::format("{} {} does not fit in 32 bits (refs are from {} to {})", what, value,
                                         std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
    return int(value);
  };
  auto read_real = [&](BinaryScanner& at) -> double {
    return format.float32() ? double(at.get_unchecked<float>()) : at.get_unchecked<double>();
  };
  auto records = [&](const char* section, std::size_t record_size) {
    auto n = read_count(in, format, section);
    in.need_records(std::uint64_t(n), record_size, fmt::format("{} records of {}", n, section));
    return n;
  };
  auto index_list = [&](const char* section, BulkVector<std::int64_t>& items, Locator& at) {
    auto n = records(section, format.int_size());
    at = Locator::bytes(in.pos(), format.int_size());
    for (std::int64_t i = 0; i < n; ++i) items.push_back(zero_based(read_index(in)));
  };
  walk_binary_keywords(in, format, [&](int code, std::size_t start) {
    switch (code) {
      case kDimension:
        dimension = read_binary_dimension(in, start);
        break;
      case kVertices: {
        const std::size_t size = std::size_t(dimension) * format.real_size() + format.int_size();
        auto n = records("Vertices", size);
        r.vertex_at = Locator::bytes(in.pos(), size);
        r.points.resize(std::size_t(n));
        r.vertex_refs.resize(std::size_t(n));
        read_records(in, n, size, [&](BinaryScanner& at, std::int64_t begin, std::int64_t end) {
          for (auto i = std::size_t(begin); i < std::size_t(end); ++i) {
            Vec3 p(0, 0, 0);
            for (int k = 0; k < dimension; ++k) p[k] = read_real(at);
            r.points[i] = p;
            r.vertex_refs[i] = read_ref(at, "a vertex ref");
          }
        });
        break;
      }
      case kTriangles: {
        const std::size_t size = 4 * format.int_size();
        auto n = records("Triangles", size);
        r.triangle_at = Locator::bytes(in.pos(), size);
        r.triangles.resize(std::size_t(n));
        r.triangle_refs.resize(std::size_t(n));
        read_records(in, n, size, [&](BinaryScanner& at, std::int64_t begin, std::int64_t end) {
          for (auto i = std::size_t(begin); i < std::size_t(end); ++i) {
            for (auto& v : r.triangles[i]) v = zero_based(read_index(at));
            r.triangle_refs[i] = read_ref(at, "a triangle ref");
          }
        });
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
          for (auto& v : e) v = zero_based(read_index(in));
          r.edge_refs[std::size_t(i)] = read_ref(in, "an edge ref");
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

/// What a Medit writer writes besides the vertices and triangles: the edges MMG must keep, the
/// lists of tags, and the vertices' numbers where deleted vertices leave gaps.
struct MeditContent {
  std::vector<std::int64_t> renumbered;  // by vertex idx, -1 for deleted; empty: a vertex's number is its idx
  std::size_t vertices = 0, faces = 0;
  std::vector<EdgeHandle> edges;  // interface, ridge, required, non-zero ref or boundary
  std::vector<std::int64_t> corners, required_vertices, ridges, required_edges;  // 1-based
  std::int64_t number(VertexHandle v) const {  // 1-based
    return (renumbered.empty() ? std::int64_t(v.idx()) : renumbered[std::size_t(v.idx())]) + 1;
  }
};

MeditContent collect(const SurfaceMesh& mesh) {
  MeditContent c;
  for_each_vertex(mesh, [&](VertexHandle) { ++c.vertices; });
  for_each_face(mesh, [&](FaceHandle) { ++c.faces; });
  if (c.vertices < mesh.n_vertices()) c.renumbered = vertex_numbering(mesh);  // deleted vertices leave gaps
  for_each_vertex(mesh, [&](VertexHandle v) {
    if (mesh.corner(v)) c.corners.push_back(c.number(v));
    if (mesh.required(v)) c.required_vertices.push_back(c.number(v));
  });
  // The edges in blocks, in parallel (five tests per edge, over every edge), then in order.
  constexpr int kBlock = 16384;
  const int ne = int(mesh.n_edges()), blocks = (ne + kBlock - 1) / kBlock;
  std::vector<std::vector<EdgeHandle>> found(std::size_t(std::max(blocks, 0)));
  tbb::parallel_for(0, blocks, [&](int b) {
    for (int i = b * kBlock; i < std::min(ne, (b + 1) * kBlock); ++i) {
      const EdgeHandle e(i);
      if (!mesh.status(e).deleted() && (mesh.interface(e) || mesh.ridge(e) || mesh.required(e) ||
                                        mesh.edge_ref(e) != 0 || mesh.is_boundary(e)))
        found[std::size_t(b)].push_back(e);
    }
  });
  for (const auto& block : found) c.edges.insert(c.edges.end(), block.begin(), block.end());
  for (std::size_t i = 0; i < c.edges.size(); ++i) {
    if (mesh.ridge(c.edges[i])) c.ridges.push_back(std::int64_t(i) + 1);
    if (mesh.required(c.edges[i])) c.required_edges.push_back(std::int64_t(i) + 1);
  }
  return c;
}

/// A triangle's corners in the order fv_range gives them (from the face's halfedge), 1-based.
std::array<std::int64_t, 3> corner_numbers(const SurfaceMesh& mesh, const MeditContent& c, FaceHandle f) {
  auto h = mesh.halfedge_handle(f);
  const auto v0 = mesh.to_vertex_handle(h);
  h = mesh.next_halfedge_handle(h);
  return {c.number(v0), c.number(mesh.to_vertex_handle(h)), c.number(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)))};
}

int written_edge_ref(const SurfaceMesh& mesh, EdgeHandle e) {
  return mesh.interface(e) ? kInterfaceRef : mesh.edge_ref(e);
}

void write_medit_text(const SurfaceMesh& mesh, const MeditContent& c, std::ostream& stream) {
  OutputBuffer out(stream);
  out.text("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n");
  out.integer(std::int64_t(c.vertices));
  out.put('\n');
  for_each_vertex(mesh, [&](VertexHandle v) {
    const auto& p = mesh.point(v);
    out.real(p[0]), out.put(' '), out.real(p[1]), out.put(' '), out.real(p[2]), out.put(' ');
    out.integer(mesh.vertex_ref(v)), out.put('\n');
  });
  out.text("\nTriangles\n");
  out.integer(std::int64_t(c.faces));
  out.put('\n');
  for_each_face(mesh, [&](FaceHandle f) {
    for (auto number : corner_numbers(mesh, c, f)) out.integer(number), out.put(' ');
    out.integer(mesh.region(f)), out.put('\n');
  });
  if (!c.edges.empty()) {
    out.text("\nEdges\n");
    out.integer(std::int64_t(c.edges.size()));
    out.put('\n');
    for (auto e : c.edges) {
      auto h = mesh.halfedge_handle(e, 0);
      out.integer(c.number(mesh.from_vertex_handle(h))), out.put(' ');
      out.integer(c.number(mesh.to_vertex_handle(h))), out.put(' ');
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

/// The binary format of a mesh, and a bound on its file's size (within a few bytes per keyword).
std::pair<BinaryFormat, std::uint64_t> binary_layout(const MeditContent& c) {
  const auto lists = c.ridges.size() + c.required_edges.size() + c.corners.size() + c.required_vertices.size();
  auto bytes = [&](std::uint64_t int_size) {
    return 8 + 10 * (12 + int_size) + c.vertices * (24 + int_size) + c.faces * 4 * int_size +
           c.edges.size() * 3 * int_size + lists * int_size;
  };
  const BinaryFormat format = binary_format_for(bytes(4));
  return {format, bytes(format.int_size())};
}

void write_medit_binary(const SurfaceMesh& mesh, const MeditContent& c, const BinaryFormat& format,
                        std::ostream& stream) {
  OutputBuffer out(stream);
  BinaryKeywordWriter w(out, format);
  const std::uint64_t is = format.int_size();
  w.begin(kDimension, 4);
  out.binary<std::int32_t>(3);
  w.begin(kVertices, is + c.vertices * (24 + is));
  w.count(std::int64_t(c.vertices));
  for_each_vertex(mesh, [&](VertexHandle v) {
    const auto& p = mesh.point(v);
    w.real(p[0]);
    w.real(p[1]);
    w.real(p[2]);
    w.integer(mesh.vertex_ref(v));
  });
  w.begin(kTriangles, is + c.faces * 4 * is);
  w.count(std::int64_t(c.faces));
  for_each_face(mesh, [&](FaceHandle f) {
    for (auto number : corner_numbers(mesh, c, f)) w.integer(number);
    w.integer(mesh.region(f));
  });
  if (!c.edges.empty()) {
    w.begin(kEdges, is + c.edges.size() * 3 * is);
    w.count(std::int64_t(c.edges.size()));
    for (auto e : c.edges) {
      auto h = mesh.halfedge_handle(e, 0);
      w.integer(c.number(mesh.from_vertex_handle(h)));
      w.integer(c.number(mesh.to_vertex_handle(h)));
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

}  // namespace

MeshRecords parse_medit(std::string_view bytes, const fs::path& file) {
  return extension_of(file) == ".meshb" ? read_medit_binary(bytes, file) : read_medit_text(bytes, file);
}

SurfaceMesh read_medit(const fs::path& file, const ReadOptions& options) {
  MeshRecords records;
  {
    const FileBytes bytes(file);
    records = parse_medit(bytes.view(), file);
  }  // the file's bytes freed: the build reuses their memory rather than fresh pages
  return build_mesh(std::move(records), file, options);
}

void write_medit(const SurfaceMesh& mesh, const fs::path& file, bool binary) {
  const MeditContent content = collect(mesh);
  if (binary) {
    const auto layout = binary_layout(content);  // not a structured binding: clang 14 cannot capture one
    write_atomically(file, [&](std::ostream& out) { write_medit_binary(mesh, content, layout.first, out); },
                     layout.second);
  } else {
    write_atomically(file, [&](std::ostream& out) { write_medit_text(mesh, content, out); });
  }
}

}  // namespace bodyfit::io_detail
