#pragma once
// Private to the io_*.cpp files: the validated mesh builder every reader goes through, and the
// locations used in error messages ("line N" for text files, "byte N" for binary ones).
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace bodyfit::io_detail {

/// Memory for the big buffers of a reader: at 2 MiB and above, with transparent huge pages
/// requested (MADV_HUGEPAGE) for the whole 2 MiB pages in it, so that filling a 6 MB array takes a
/// few page faults instead of 1500 — on the machines measured a fault per 4 KiB page cost more than
/// parsing that page, and a command reads its mesh into memory it never touched before.
void* bulk_allocate(std::size_t bytes);
void bulk_free(void* p, std::size_t bytes);
inline constexpr std::size_t kBulkThreshold = std::size_t(2) << 20;

template <class T>
struct BulkAllocator {
  using value_type = T;
  BulkAllocator() = default;
  template <class U>
  BulkAllocator(const BulkAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    if (n * sizeof(T) < kBulkThreshold) return std::allocator<T>().allocate(n);
    return static_cast<T*>(bulk_allocate(n * sizeof(T)));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kBulkThreshold) std::allocator<T>().deallocate(p, n);
    else bulk_free(p, n * sizeof(T));
  }
  /// An element made without a value (resize(n), emplace_back()) is left default-initialised, not
  /// zeroed: every reader writes each record it sizes for, and zeroing them first costs as much as
  /// a fast parse.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  friend bool operator==(const BulkAllocator&, const BulkAllocator&) { return true; }
};
template <class T>
using BulkVector = std::vector<T, BulkAllocator<T>>;

/// Where record i of a section starts: a line per record (text) or start + i·stride bytes (binary).
class Locator {
 public:
  static Locator lines() { return Locator(); }
  static Locator bytes(std::uint64_t start, std::uint64_t stride) {
    Locator l;
    l.binary_ = true;
    l.start_ = start;
    l.stride_ = stride;
    return l;
  }
  static Locator none() {
    Locator l;
    l.none_ = true;
    return l;
  }
  void push_line(long line) {
    if (!binary_ && !none_) lines_.push_back(static_cast<std::uint32_t>(line));
  }
  void reserve(std::size_t n) {
    if (!binary_ && !none_) lines_.reserve(n);
  }
  /// n records, one per line from `first`.
  void push_lines(long first, std::size_t n) {
    if (binary_ || none_) return;
    const std::size_t at = lines_.size();
    lines_.resize(at + n);
    for (std::size_t i = 0; i < n; ++i) lines_[at + i] = static_cast<std::uint32_t>(first + long(i));
  }
  /// The error for record i: "<file>:<line>: what", "<file>: byte N: what" or "<file>: what".
  InputError error(const std::filesystem::path& file, std::size_t i, const std::string& what) const;

 private:
  bool binary_ = false;
  bool none_ = false;
  std::uint64_t start_ = 0, stride_ = 0;
  BulkVector<std::uint32_t> lines_;
};

/// A mesh as read from a file, before validation. Indices are 0-based.
struct MeshRecords {
  BulkVector<Vec3> points;
  BulkVector<int> vertex_refs;
  Locator vertex_at;
  BulkVector<std::array<std::int64_t, 3>> triangles;
  BulkVector<int> triangle_refs;
  Locator triangle_at;
  BulkVector<std::array<std::int64_t, 2>> edges;
  BulkVector<int> edge_refs;
  Locator edge_at;
  // Indices (0-based) into points or edges; each with its own locator.
  BulkVector<std::int64_t> corners, required_vertices, ridges, required_edges;
  Locator corner_at, required_vertex_at, ridge_at, required_edge_at;
};

/// Check everything (finite coordinates, indices in range, no degenerate, duplicate or zero-area
/// triangle, manifold edges and vertices, consistent orientation) and build the mesh with its
/// refs and tags. Throws InputError located with the records' locators.
SurfaceMesh build_mesh(MeshRecords&& records, const std::filesystem::path& file, const ReadOptions& options);

/// Lower-case extension with its dot (".mesh").
std::string extension_of(const std::filesystem::path& file);

/// The whole file in memory; InputError when it cannot be opened or read.
std::string read_file_bytes(const std::filesystem::path& file);

/// The whole file in memory, read by pieces on every thread into huge-page memory (bulk_allocate)
/// when it is a big regular file: a 12 MB mesh then costs a few page faults instead of 3000, which
/// cost more than parsing it. InputError when it cannot be opened or read.
class FileBytes {
 public:
  explicit FileBytes(const std::filesystem::path& file);
  ~FileBytes();
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  std::string_view view() const { return data_ ? std::string_view(data_, size_) : std::string_view(copy_); }

 private:
  char* data_ = nullptr;
  std::size_t size_ = 0, capacity_ = 0;
  std::string copy_;
};

/// Calls visit(element) for each live vertex or face in index order, what mesh.vertices() and
/// mesh.faces() give, as a plain loop for the writers: OpenMesh's skipping iterator is inlined or
/// not as a file's other code leaves the compiler's budget, and called out of line it cost a third
/// of a .meshb write.
template <class Handle, class Visit>
void for_each_live(const SurfaceMesh& mesh, std::size_t n, Visit&& visit) {
  for (std::size_t i = 0; i < n; ++i)
    if (const Handle h{int(i)}; !mesh.status(h).deleted()) visit(h);
}
template <class Visit>
void for_each_vertex(const SurfaceMesh& mesh, Visit&& visit) {
  for_each_live<VertexHandle>(mesh, mesh.n_vertices(), visit);
}
template <class Visit>
void for_each_face(const SurfaceMesh& mesh, Visit&& visit) {
  for_each_live<FaceHandle>(mesh, mesh.n_faces(), visit);
}

/// Compact vertex indices (skipping deleted vertices): index[v.idx()] = position in the output.
std::vector<std::int64_t> vertex_numbering(const SurfaceMesh& mesh);

// Per-format entry points.
/// The records of a Medit file's bytes (.meshb by extension, else text), before build_mesh.
MeshRecords parse_medit(std::string_view bytes, const std::filesystem::path& file);
SurfaceMesh read_medit(const std::filesystem::path& file, const ReadOptions& options);
void write_medit(const SurfaceMesh& mesh, const std::filesystem::path& file, bool binary);
/// The records of an OFF file's bytes (text or binary), before build_mesh.
MeshRecords parse_off(std::string_view bytes, const std::filesystem::path& file);
SurfaceMesh read_off(const std::filesystem::path& file, const ReadOptions& options);
/// The records of an OBJ file's bytes, before build_mesh.
MeshRecords parse_obj(std::string_view bytes, const std::filesystem::path& file);
SurfaceMesh read_obj(const std::filesystem::path& file, const ReadOptions& options);
/// The records of a PLY file's bytes (ASCII or binary), before build_mesh.
MeshRecords parse_ply(std::string_view bytes, const std::filesystem::path& file);
SurfaceMesh read_ply(const std::filesystem::path& file, const ReadOptions& options);
/// STL through OpenMesh's reader.
SurfaceMesh read_openmesh_format(const std::filesystem::path& file, const ReadOptions& options);
void write_openmesh_format(const SurfaceMesh& mesh, const std::filesystem::path& file);

}  // namespace bodyfit::io_detail
