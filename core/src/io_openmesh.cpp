// OBJ, OFF, PLY and STL through OpenMesh's readers and writers. The reader's result is turned back
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
#include <charconv>
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

/// The next whitespace-separated word of `text` from `at` on, skipping '#' comments (OFF), "" at the end.
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

/// A count of the header: a non-negative integer, else an InputError naming it.
std::uint64_t header_count(std::string_view word, const std::filesystem::path& file, const char* what) {
  std::int64_t value = -1;
  auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (ec != std::errc() || ptr != word.data() + word.size() || value < 0)
    throw file_error(file, fmt::format("the header's {} '{}' is not a count (a non-negative integer)", what, word));
  return std::uint64_t(value);
}

/// The counts a header declares must fit in the file (each record takes at least a few bytes),
/// before OpenMesh reserves memory for them: a damaged header is an error, not a 137 GB allocation
/// or an empty mesh. STL: a file that is not ASCII ("solid ...") is binary, whose size is exact.
void check_declared_counts(std::string_view bytes, const std::string& ext, const std::filesystem::path& file) {
  const std::uint64_t size = bytes.size();
  auto needs = [](std::uint64_t vertices, std::uint64_t faces, double vertex_bytes, double face_bytes) {
    return double(vertices) * vertex_bytes + double(faces) * face_bytes;
  };
  auto fits = [&](std::uint64_t vertices, std::uint64_t faces, double vertex_bytes, double face_bytes) {
    const double needed = needs(vertices, faces, vertex_bytes, face_bytes);
    if (needed > double(size))
      throw file_error(file, fmt::format("the header declares {} vertices and {} faces, which need at least {:.0f} "
                                         "bytes; the file has {} (truncated or not this format?)",
                                         vertices, faces, needed, size));
  };
  if (ext == ".stl") {
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
  } else if (ext == ".off") {
    std::size_t at = 0;
    const std::string_view keyword = next_word(bytes, at);
    if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF")
      throw file_error(file, "not an OFF file: it does not start with 'OFF'");
    std::size_t after = at;
    const bool binary = next_word(bytes, after) == "BINARY";
    if (binary) {
      if (size < after + 12) throw file_error(file, "binary OFF: truncated header");
      std::uint32_t counts[2];
      std::memcpy(counts, bytes.data() + after + 1, 8);  // after the newline that ends "BINARY"
      // Either byte order (writers differ): refused only when neither fits.
      if (needs(counts[0], counts[1], 12, 16) > double(size))
        fits(__builtin_bswap32(counts[0]), __builtin_bswap32(counts[1]), 12, 16);
    } else {
      const std::uint64_t vertices = header_count(next_word(bytes, at), file, "vertex count");
      const std::uint64_t faces = header_count(next_word(bytes, at), file, "face count");
      fits(vertices, faces, 6, 8);  // "0 0 0\n", "3 0 1 2\n"
    }
  } else if (ext == ".ply") {
    const std::size_t end = bytes.find("end_header");
    if (end == std::string_view::npos) throw file_error(file, "not a PLY file: no 'end_header'");
    std::uint64_t counts[2] = {0, 0};
    for (std::size_t at = 0; at < end;) {
      const std::string_view word = next_word(bytes, at);
      if (word != "element") continue;
      const std::string_view name = next_word(bytes, at);
      const std::uint64_t n = header_count(next_word(bytes, at), file, "element count");
      if (name == "vertex") counts[0] = n;
      if (name == "face") counts[1] = n;
    }
    fits(counts[0], counts[1], 3, 4);  // the smallest binary records
  }
}

/// OpenMesh's OFF reader trusts the numbers of the file (found by fuzz_openmesh): besides the
/// header's counts (check_declared_counts, run first), it reads as many indices as a face's first
/// number says, past the end of the file too (a face of −1 corners: 4·10^9 reads, a hang). A face
/// has at most as many corners as there are vertices: checked in plain ASCII OFF (the header "OFF":
/// 3 coordinates a vertex).
void check_off_faces(const std::string& bytes, const std::filesystem::path& file) {
  const auto line_end = bytes.find('\n');
  if (line_end == std::string::npos) return;  // no counts: OpenMesh refuses the file itself
  const std::string header = bytes.substr(0, line_end);
  if (header.find("OFF") == std::string::npos) return;
  const bool binary = header.find("BINARY") != std::string::npos;
  long long vertices = 0, faces = 0;
  std::istringstream in;
  if (binary) {
    // 32-bit counts after the header line, in an order OpenMesh chooses: the smaller reading of each.
    if (bytes.size() < line_end + 1 + 8) return;
    auto count = [&](std::size_t at) {
      std::uint32_t le = 0;
      std::memcpy(&le, bytes.data() + at, 4);
      const std::uint32_t be = (le >> 24) | ((le >> 8) & 0xff00u) | ((le << 8) & 0xff0000u) | (le << 24);
      return static_cast<long long>(std::min(le, be));
    };
    vertices = count(line_end + 1);
    faces = count(line_end + 5);
  } else {
    // The counts follow the magic word, on its line or the next.
    in.str(bytes);
    std::string magic;
    in >> magic;
    if (header.find("nOFF") != std::string::npos) {
      long long dimension = 0;
      in >> dimension;
    }
    long long edges = 0;  // (unused by OpenMesh)
    if (!(in >> vertices >> faces >> edges)) return;  // OpenMesh reports malformed counts
  }
  std::string magic_word;
  std::istringstream(header) >> magic_word;
  if (binary || magic_word != "OFF") return;
  auto check_corners = [&](long long face, const std::string& word) {
    long long corners = 0;
    const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), corners);
    if (error != std::errc() || end != word.data() + word.size()) return false;  // OpenMesh's error
    if (corners < 0 || corners > vertices)
      throw file_error(file, fmt::format("OFF face {} has {} corners, expected 3 to {} (the number of vertices)",
                                         face, corners, vertices));
    return true;
  };
  // A malformed file may be read a vertex a line or a number at a time: both readings are checked
  // (they agree on a well-formed file).
  const auto after_counts = in.tellg();
  std::string line;
  std::getline(in, line);  // the rest of the counts' line
  auto first_word = [&]() {
    while (std::getline(in, line)) {
      std::string word;
      std::istringstream(line) >> word;
      if (!word.empty() && word[0] != '#') return word;
    }
    return std::string();
  };
  for (long long v = 0; v < vertices && !first_word().empty(); ++v) continue;
  for (long long face = 1; face <= faces; ++face) {
    const std::string word = first_word();
    if (word.empty() || !check_corners(face, word)) break;
  }
  in.clear();
  in.seekg(after_counts);
  std::string word;
  auto skip = [&](long long numbers) {
    while (numbers-- > 0 && in >> word) continue;
  };
  skip(3 * vertices);
  for (long long face = 1; face <= faces && in >> word; ++face) {
    if (!check_corners(face, word)) return;
    skip(std::stoll(word));
  }
}

}  // namespace

SurfaceMesh read_openmesh_format(const std::filesystem::path& file, const ReadOptions& options) {
  // A clear error for a missing or unreadable file, for counts the file cannot hold and for OFF
  // faces OpenMesh would read past the end of the file.
  const std::string bytes = read_file_bytes(file);
  check_declared_counts(bytes, extension_of(file), file);
  if (extension_of(file) == ".off") check_off_faces(bytes, file);
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
