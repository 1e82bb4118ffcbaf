// STL through OpenMesh's reader, and OBJ, OFF, PLY and STL through its writers (OFF, OBJ and PLY
// are read by io_off.cpp, io_obj.cpp and io_ply.cpp). The reader's result is turned back
// into plain records and rebuilt by the validated builder, so these formats get the same checks
// as Medit files. OpenMesh's importer repairs non-manifold input silently (it duplicates the
// vertices of a face it cannot add and marks it "fixed non-manifold") and reports other problems
// only on omerr: both are turned into an InputError.
#include "io_internal.hpp"

#include <bodyfit/atomic_file.hpp>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string_view>

namespace bodyfit::io_detail {
namespace {

/// Collect what OpenMesh prints on omerr while in scope (instead of letting it reach stderr).
/// omerr writes to std::cerr: its buffer is swapped for ours. (Not omerr().connect/disconnect:
/// OpenMesh's disconnect never deletes the target that connect allocated, a leak per call.)
class CaptureOpenMeshErrors {
 public:
  CaptureOpenMeshErrors() : log_was_enabled_(omlog().is_enabled()) {
    omerr().flush();
    cerr_buffer_ = std::cerr.rdbuf(captured_.rdbuf());
    omlog().disable();  // OpenMesh's writers log "[OBJWriter] : write file" on every call
  }
  ~CaptureOpenMeshErrors() {
    omerr().flush();
    std::cerr.rdbuf(cerr_buffer_);
    if (log_was_enabled_) omlog().enable();
  }
  CaptureOpenMeshErrors(const CaptureOpenMeshErrors&) = delete;
  CaptureOpenMeshErrors& operator=(const CaptureOpenMeshErrors&) = delete;
  /// The first line printed so far (empty when nothing was).
  std::string first_line() {
    omerr().flush();
    std::string text = captured_.str();
    auto end = text.find('\n');
    text = text.substr(0, end);
    while (!text.empty() && (text.back() == '\r' || text.back() == ' ')) text.pop_back();
    return text;
  }

 private:
  std::ostringstream captured_;
  std::streambuf* cerr_buffer_ = nullptr;
  bool log_was_enabled_ = true;
};

/// The next whitespace-separated word of `text` from `at` on, skipping '#' comments, "" at the end.
std::string_view next_word(std::string_view text, std::size_t& at) {
  for (;;) {
    while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at]))) ++at;
    if (at < text.size() && text[at] == '#') {
      while (at < text.size() && text[at] != '\n') ++at;
      continue;
    }
    break;
  }
  const std::size_t start = at;
  while (at < text.size() && !std::isspace(static_cast<unsigned char>(text[at]))) ++at;
  return text.substr(start, at - start);
}

/// A binary STL's size is exact (84 + 50 per triangle), checked before OpenMesh reserves memory
/// for its count: a damaged header is an error, not a huge allocation or an empty mesh. A file
/// that starts with "solid" is ASCII.
void check_stl_size(std::string_view bytes, const std::filesystem::path& file) {
  const std::uint64_t size = bytes.size();
  std::size_t at = 0;
  const bool ascii = next_word(bytes, at) == "solid";
  std::uint32_t triangles = 0;
  if (size >= 84) std::memcpy(&triangles, bytes.data() + 80, 4);  // little-endian, as the format
  const std::uint64_t binary_size = 84 + 50 * std::uint64_t(triangles);
  if (!ascii && (size < 84 || binary_size != size))
    throw file_error(file, size < 84 ? fmt::format("not an STL file: no 'solid' line and {} bytes, less than a "
                                                   "binary STL's 84-byte header",
                                                   size)
                                     : fmt::format("binary STL: the header declares {} triangles ({} bytes), the "
                                                   "file has {} bytes (truncated or not an STL file?)",
                                                   triangles, binary_size, size));
}

}  // namespace

SurfaceMesh read_openmesh_format(const std::filesystem::path& file, const ReadOptions& options) {
  // A clear error for a missing or unreadable file and for counts the file cannot hold.
  const std::string bytes = read_file_bytes(file);
  if (extension_of(file) == ".stl") check_stl_size(bytes, file);
  SurfaceMesh raw;
  OpenMesh::IO::Options io_options;
  std::string complaint;
  bool ok = false;
  {
    CaptureOpenMeshErrors capture;
    ok = OpenMesh::IO::read_mesh(raw, file.string(), io_options);
    complaint = capture.first_line();
  }
  if (!ok)
    throw file_error(file, complaint.empty() ? std::string("OpenMesh could not read this file (malformed?)")
                                             : "OpenMesh could not read this file: " + complaint);
  for (auto f : raw.faces())
    if (raw.status(f).fixed_nonmanifold())
      throw file_error(file, fmt::format("face {} makes a non-manifold edge or vertex (OpenMesh had to duplicate its "
                                         "vertices to read it)",
                                         f.idx() + 1));
  if (!complaint.empty()) throw file_error(file, "OpenMesh reported a problem: " + complaint);

  MeshRecords records;
  records.vertex_at = records.triangle_at = Locator::none();
  records.points.reserve(raw.n_vertices());
  for (auto v : raw.vertices()) records.points.push_back(raw.point(v));
  records.triangles.reserve(raw.n_faces());
  for (auto f : raw.faces()) {
    std::array<std::int64_t, 3> tri{};
    int k = 0;
    for (auto v : raw.fv_range(f)) tri[k++] = v.idx();
    records.triangles.push_back(tri);
  }
  return build_mesh(std::move(records), file, options);
}

void write_openmesh_format(const SurfaceMesh& mesh, const std::filesystem::path& file) {
  const std::string ext = extension_of(file);
  const SurfaceMesh* source = &mesh;
  SurfaceMesh compacted;
  if (mesh.n_vertices() != std::size_t(std::distance(mesh.vertices().begin(), mesh.vertices().end())) ||
      mesh.n_faces() != std::size_t(std::distance(mesh.faces().begin(), mesh.faces().end()))) {
    // Rebuild in order (garbage_collection would move the last elements into the holes), so
    // every format numbers vertices and faces the same way.
    const auto index = vertex_numbering(mesh);
    for (auto v : mesh.vertices()) compacted.add_vertex(mesh.point(v));
    for (auto f : mesh.faces()) {
      std::vector<VertexHandle> corners;
      for (auto v : mesh.fv_range(f)) corners.push_back(VertexHandle(int(index[std::size_t(v.idx())])));
      compacted.add_face(corners);
    }
    source = &compacted;
  }
  write_atomically(file, [&](std::ostream& out) {
    std::string complaint;
    bool ok = false;
    {
      CaptureOpenMeshErrors capture;
      ok = OpenMesh::IO::write_mesh(*source, out, ext, OpenMesh::IO::Options::Default, 17);
      complaint = capture.first_line();
    }
    if (!ok) throw file_error(file, "OpenMesh could not write this format" + (complaint.empty() ? "" : ": " + complaint));
  });
}

}  // namespace bodyfit::io_detail
