// Mesh I/O: format dispatch and the validated builder shared by every reader.
#include "blocks.hpp"
#include "io_internal.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/mesh_connectivity.hpp>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <numeric>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <vector>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace bodyfit {
namespace io_detail {

InputError Locator::error(const std::filesystem::path& file, std::size_t i, const std::string& what) const {
  if (none_) return file_error(file, what);
  if (binary_) return file_error(file, fmt::format("byte {}: {}", start_ + i * stride_, what));
  if (i < lines_.size()) return file_error(file, static_cast<long>(lines_[i]), what);
  return file_error(file, what);
}

std::string extension_of(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::string read_file_bytes(const std::filesystem::path& file) {
  return std::string(FileBytes(file).view());
}

FileBytes::FileBytes(const std::filesystem::path& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw file_error(file, fmt::format("cannot open for reading ({})", std::strerror(errno)));
  struct stat st {};
  const bool stated = ::fstat(fd, &st) == 0;
  if (stated && S_ISDIR(st.st_mode)) {
    ::close(fd);
    throw file_error(file, "cannot read: it is a directory");
  }
  auto fail = [&](int error) {
    ::close(fd);
    return file_error(file, fmt::format("read error ({})", std::strerror(error)));
  };
  if (stated && S_ISREG(st.st_mode) && std::size_t(st.st_size) >= kBulkThreshold) {
    // A big regular file: read into huge-page memory (bulk_allocate) by pieces, one per thread:
    // the kernel's copy from the page cache is most of the time a read takes, and runs on each.
    capacity_ = std::size_t(st.st_size);
    data_ = static_cast<char*>(bulk_allocate(capacity_));
    const int pieces = std::clamp(int(capacity_ / kBulkThreshold), 1, tbb::this_task_arena::max_concurrency());
    auto piece_begin = [&](int i) {  // on a page
      return i == pieces ? capacity_ : capacity_ * std::size_t(i) / std::size_t(pieces) / 4096 * 4096;
    };
    std::vector<std::size_t> got(std::size_t(pieces), 0);
    std::vector<int> error(std::size_t(pieces), 0);
    tbb::parallel_for(0, pieces, [&](int i) {
      const std::size_t begin = piece_begin(i), end = piece_begin(i + 1);
      std::size_t& done = got[std::size_t(i)];
      while (begin + done < end) {
        const ssize_t n = ::pread(fd, data_ + begin + done, end - begin - done, off_t(begin + done));
        if (n == 0) break;  // shrunk meanwhile
        if (n < 0) {
          if (errno == EINTR) continue;
          error[std::size_t(i)] = errno;
          break;
        }
        done += std::size_t(n);
      }
    });
    for (const int e : error)
      if (e) {
        bulk_free(data_, capacity_);
        data_ = nullptr;
        throw fail(e);
      }
    // What there is from the start: less than the size when the file shrank meanwhile.
    for (int i = 0; i < pieces && size_ == piece_begin(i); ++i) size_ += got[std::size_t(i)];
    ::close(fd);
    return;
  }
  // Small files, pipes, /proc: read in blocks. What is not a regular file has no size to trust:
  // a device such as /dev/zero never ends, so a stream is read up to a bound.
  const bool regular = stated && S_ISREG(st.st_mode);
  if (regular) copy_.reserve(std::size_t(st.st_size));
  constexpr std::size_t kStreamLimit = std::size_t(1) << 30;
  char chunk[1 << 16];
  for (;;) {
    const ssize_t got = ::read(fd, chunk, sizeof chunk);
    if (got == 0) break;
    if (got < 0) {
      if (errno == EINTR) continue;
      throw fail(errno);
    }
    if (!regular && copy_.size() + std::size_t(got) > kStreamLimit) {  // checked first: no 2 GiB growth
      ::close(fd);
      throw file_error(file, fmt::format("not a regular file, and still going after {} GiB (a device such as "
                                         "/dev/zero?): save it to a file first",
                                         kStreamLimit >> 30));
    }
    copy_.append(chunk, std::size_t(got));
  }
  ::close(fd);
}

FileBytes::~FileBytes() {
  if (data_) bulk_free(data_, capacity_);
}

void* bulk_allocate(std::size_t bytes) {
  // From malloc, not aligned_alloc: the ends aligned_alloc splits off are taken by small blocks,
  // and pinned between them the freed big blocks no longer fit the next read's, which grows the
  // heap into fresh pages every time. A process that already freed such blocks gets them back,
  // faulted in. The block's whole 2 MiB pages are asked to be huge (a hint; a heap on huge pages,
  // glibc.malloc.hugetlb=1, already is).
  void* p = std::malloc(bytes);
  if (!p) throw std::bad_alloc();
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t begin = (at + kBulkThreshold - 1) / kBulkThreshold * kBulkThreshold;
  const std::uintptr_t end = (at + bytes) / kBulkThreshold * kBulkThreshold;
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  return p;
}

void bulk_free(void* p, std::size_t) { std::free(p); }

std::vector<std::int64_t> vertex_numbering(const SurfaceMesh& mesh) {
  std::vector<std::int64_t> index(mesh.n_vertices(), -1);
  std::int64_t next = 0;
  for (auto v : mesh.vertices()) index[v.idx()] = next++;
  return index;
}

namespace {

/// Coordinates beyond this would overflow squared lengths and cross products.
constexpr double kMaxCoordinate = 1e100;

/// Diagnose why OpenMesh refused triangle (a, b, c): an edge already used twice, an edge used
/// once with the same orientation (a duplicate triangle or an inconsistent orientation), or else
/// a vertex whose fan cannot take one more triangle.
std::string diagnose_refused_triangle(const SurfaceMesh& mesh, const std::array<VertexHandle, 3>& v) {
  for (int k = 0; k < 3; ++k) {
    auto a = v[k], b = v[(k + 1) % 3];
    auto h = mesh.find_halfedge(a, b);
    if (!h.is_valid() || mesh.is_boundary(h)) continue;
    auto opposite = mesh.opposite_halfedge_handle(h);
    if (!mesh.is_boundary(opposite))
      return fmt::format("non-manifold edge {}-{}: it already borders two triangles", a.idx() + 1, b.idx() + 1);
    auto f = mesh.face_handle(h);
    std::array<int, 3> mine{v[0].idx(), v[1].idx(), v[2].idx()}, theirs{};
    int i = 0;
    for (auto w : mesh.fv_range(f)) theirs[i++] = w.idx();
    std::sort(mine.begin(), mine.end());
    std::sort(theirs.begin(), theirs.end());
    if (mine == theirs) return fmt::format("duplicate triangle (same vertices as triangle {})", f.idx() + 1);
    return fmt::format("inconsistent orientation: edge {}-{} is traversed in the same direction by triangle {}",
                       a.idx() + 1, b.idx() + 1, f.idx() + 1);
  }
  return "non-manifold vertex: a vertex of this triangle already has a closed fan of triangles or would join two "
         "fans";
}

/// The halfedge a→b or b→a, invalid when a-b is not a mesh edge.
EdgeHandle find_edge(const SurfaceMesh& mesh, VertexHandle a, VertexHandle b) {
  auto h = mesh.find_halfedge(a, b);
  return h.is_valid() ? mesh.edge_handle(h) : EdgeHandle();
}

/// OpenMesh prints to omerr when add_face fails; the builder reports the failure itself.
class SilenceOpenMeshErrors {
 public:
  SilenceOpenMeshErrors() : was_enabled_(omerr().is_enabled()) { omerr().disable(); }
  ~SilenceOpenMeshErrors() {
    if (was_enabled_) omerr().enable();
  }
  SilenceOpenMeshErrors(const SilenceOpenMeshErrors&) = delete;
  SilenceOpenMeshErrors& operator=(const SilenceOpenMeshErrors&) = delete;

 private:
  bool was_enabled_;
};

}  // namespace

/// The records with every set of vertices at one point made one (the first of each, in order),
/// the others dropped and the indices renumbered; `merged` counts the dropped ones. Locators are
/// not kept (what is built from it names no line).
MeshRecords merge_coincident_vertices(const MeshRecords& r, std::size_t& merged) {
  const std::size_t n = r.points.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t(0));
  auto coordinates = [&](std::size_t i) { return std::array<double, 3>{r.points[i][0], r.points[i][1], r.points[i][2]}; };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return coordinates(a) < coordinates(b); });
  std::vector<std::size_t> first(n);
  for (std::size_t k = 0; k < n; ++k)
    first[order[k]] = k > 0 && coordinates(order[k]) == coordinates(order[k - 1]) ? first[order[k - 1]] : order[k];
  MeshRecords out;
  out.vertex_at = out.triangle_at = out.edge_at = Locator::none();
  out.corner_at = out.required_vertex_at = out.ridge_at = out.required_edge_at = Locator::none();
  std::vector<std::int64_t> index(n, -1);
  merged = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (first[i] != i) {
      ++merged;
      continue;
    }
    index[i] = std::int64_t(out.points.size());
    out.points.push_back(r.points[i]);
    if (i < r.vertex_refs.size()) out.vertex_refs.push_back(r.vertex_refs[i]);
  }
  auto renumbered = [&](std::int64_t i) { return index[first[std::size_t(i)]]; };
  for (const auto& t : r.triangles) out.triangles.push_back({renumbered(t[0]), renumbered(t[1]), renumbered(t[2])});
  out.triangle_refs = r.triangle_refs;
  for (const auto& e : r.edges) out.edges.push_back({renumbered(e[0]), renumbered(e[1])});
  out.edge_refs = r.edge_refs;
  for (auto v : r.corners) out.corners.push_back(renumbered(v));
  for (auto v : r.required_vertices) out.required_vertices.push_back(renumbered(v));
  out.ridges = r.ridges;
  out.required_edges = r.required_edges;
  return out;
}

namespace {
/// The first i in [0, n) for which bad(i) holds, or n.
template <class Bad>
int first_where(int n, Bad&& bad) {
  return reduce(
      n, n, [&](int i, int& first) { if (i < first && bad(i)) first = i; },
      [](int& first, int other) { first = std::min(first, other); });
}
}  // namespace

SurfaceMesh build_mesh(MeshRecords&& r, const std::filesystem::path& file, const ReadOptions& options) {
  // Every check runs in parallel and names the first record that fails it, as a loop would.
  constexpr std::size_t kMostElements = std::numeric_limits<int>::max() / 3;  // int handles, 3 sides each
  if (r.points.size() > kMostElements || r.triangles.size() > kMostElements)
    throw file_error(file, fmt::format("{} vertices and {} triangles: more than a mesh can hold ({} of each)",
                                       r.points.size(), r.triangles.size(), kMostElements));
  const std::int64_t nv = static_cast<std::int64_t>(r.points.size());
  const int bad_vertex = first_where(int(nv), [&](int i) {
    const auto& p = r.points[std::size_t(i)];
    return !std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) ||
           std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) > kMaxCoordinate;
  });
  if (bad_vertex < nv) {
    const auto i = std::size_t(bad_vertex);
    const auto& p = r.points[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw r.vertex_at.error(file, i, fmt::format("vertex {} has a NaN or infinite coordinate", i + 1));
    throw r.vertex_at.error(file, i,
                            fmt::format("vertex {} ({:.3g}, {:.3g}, {:.3g}) is beyond ±{:.0e}: its squared lengths and "
                                        "areas would overflow",
                                        i + 1, p[0], p[1], p[2], kMaxCoordinate));
  }
  if (r.triangles.empty())
    throw file_error(file, fmt::format("no triangles ({} vertices): not a surface mesh, or a truncated or "
                                       "malformed file",
                                       r.points.size()));

  // Indices, degenerate triangles and the mesh scale, in one sweep: the first bad triangle, and
  // over the others the sides' total length (by fixed blocks: the same for any number of threads)
  // and the least area, taken of the squared cross products (one square root in all, the same
  // number: a square root never reorders). The first triangle too small is looked for only when
  // the least one is.
  const int nt = int(r.triangles.size());
  auto bad = [&](const std::array<std::int64_t, 3>& tri) {
    for (auto i : tri)
      if (i < 0 || i >= nv) return true;
    return tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
  };
  struct Scale {
    int first_bad = std::numeric_limits<int>::max();
    double length = 0, least_cross2 = std::numeric_limits<double>::infinity();
  };
  const Scale scale = reduce(
      nt, Scale{},
      [&](int t, Scale& s) {
        const auto& tri = r.triangles[std::size_t(t)];
        if (bad(tri)) {
          s.first_bad = std::min(s.first_bad, t);
          return;
        }
        const Vec3 &a = r.points[std::size_t(tri[0])], &b = r.points[std::size_t(tri[1])], &c = r.points[std::size_t(tri[2])];
        s.length += (b - a).norm() + (c - b).norm() + (a - c).norm();
        if (const double cross2 = OpenMesh::cross(b - a, c - a).sqrnorm(); !(cross2 >= s.least_cross2))
          s.least_cross2 = cross2;  // a NaN too
      },
      [](Scale& total, const Scale& s) {
        total.first_bad = std::min(total.first_bad, s.first_bad);
        total.length += s.length;
        if (!(s.least_cross2 >= total.least_cross2)) total.least_cross2 = s.least_cross2;
      });
  if (scale.first_bad < nt) {
    const auto t = std::size_t(scale.first_bad);
    const auto& tri = r.triangles[t];
    for (auto i : tri)
      if (i < 0 || i >= nv)
        throw r.triangle_at.error(file, t,
                                  fmt::format("triangle {} refers to vertex {}, expected an index in 1..{}", t + 1,
                                              i + 1, nv));
    throw r.triangle_at.error(file, t, fmt::format("triangle {} uses the same vertex twice", t + 1));
  }
  auto area = [&](int t) {
    const auto& tri = r.triangles[std::size_t(t)];
    return 0.5 * OpenMesh::cross(r.points[tri[1]] - r.points[tri[0]], r.points[tri[2]] - r.points[tri[0]]).norm();
  };
  const double least_area = 0.5 * std::sqrt(scale.least_cross2);
  const double mean_length = scale.length / (3.0 * double(nt));
  const double min_area = options.min_relative_area * mean_length * mean_length;
  const int flat = least_area > min_area ? nt : first_where(nt, [&](int t) { return !(area(t) > min_area); });
  if (flat < nt)
    throw r.triangle_at.error(file, std::size_t(flat),
                              fmt::format("triangle {} has zero area ({:.3g}, below {:.3g} x mean edge length^2)",
                                          flat + 1, area(flat), options.min_relative_area));

  SurfaceMesh mesh;
  // Room for an eighth more of each (never touched, so no memory until used): the cut and remesh
  // that usually follow a read add a few per cent, and each growth beyond the arrays' size would
  // copy every one of them.
  auto with_room = [](std::size_t n) { return n + n / 8; };
  mesh.reserve(with_room(r.points.size()), with_room(r.points.size() + r.triangles.size()), with_room(r.triangles.size()));
  // The vertices at once (add_vertex grows every vertex property by one, vertex after vertex).
  mesh.resize(r.points.size(), 0, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r.points.size(), 4096), [&](const auto& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      const auto v = VertexHandle(int(i));
      mesh.set_point(v, r.points[i]);
      mesh.vertex_ref(v) = i < r.vertex_refs.size() ? r.vertex_refs[i] : 0;
    }
  });
  // The connectivity in a few array passes; triangle by triangle only to say what is wrong.
  if (build_connectivity(mesh, {r.triangles.data(), r.triangles.size()})) {
    for_each_index(int(std::min(r.triangles.size(), r.triangle_refs.size())),
                   [&](int t) { mesh.region(FaceHandle(t)) = r.triangle_refs[std::size_t(t)]; });
  } else {
    SilenceOpenMeshErrors silence;
    for (std::size_t t = 0; t < r.triangles.size(); ++t) {
      const auto& tri = r.triangles[t];
      std::array<VertexHandle, 3> v{VertexHandle(int(tri[0])), VertexHandle(int(tri[1])), VertexHandle(int(tri[2]))};
      // A triangle with the opposite orientation of an existing one would be accepted: catch it first.
      auto h = mesh.find_halfedge(v[1], v[0]);
      if (h.is_valid() && !mesh.is_boundary(h) && mesh.to_vertex_handle(mesh.next_halfedge_handle(h)) == v[2])
        throw r.triangle_at.error(
            file, t,
            fmt::format("triangle {} is a duplicate (same vertices as triangle {}, opposite orientation)", t + 1,
                        mesh.face_handle(h).idx() + 1));
      auto f = mesh.add_face(v[0], v[1], v[2]);
      if (!f.is_valid())
        throw r.triangle_at.error(file, t, fmt::format("triangle {}: {}", t + 1, diagnose_refused_triangle(mesh, v)));
      mesh.region(f) = t < r.triangle_refs.size() ? r.triangle_refs[t] : 0;
    }
    // A vertex where two fans touch has two outgoing boundary halfedges (add_face accepts it;
    // build_connectivity refuses it).
    std::vector<char> boundary_out(mesh.n_vertices(), 0);
    for (auto h : mesh.halfedges()) {
      if (!mesh.is_boundary(h)) continue;
      auto v = mesh.from_vertex_handle(h);
      if (boundary_out[v.idx()]++)
        throw r.vertex_at.error(file, std::size_t(v.idx()),
                                fmt::format("vertex {} is non-manifold: two separate fans of triangles meet there",
                                            v.idx() + 1));
    }
  }

  // Edges and their tags.
  std::vector<EdgeHandle> listed(r.edges.size());
  for (std::size_t i = 0; i < r.edges.size(); ++i) {
    auto [a, b] = r.edges[i];
    if (a < 0 || a >= nv || b < 0 || b >= nv)
      throw r.edge_at.error(file, i,
                            fmt::format("edge {} refers to vertex {}, expected an index in 1..{}", i + 1,
                                        (a < 0 || a >= nv) ? a + 1 : b + 1, nv));
    auto e = find_edge(mesh, VertexHandle(int(a)), VertexHandle(int(b)));
    if (!e.is_valid())
      throw r.edge_at.error(file, i, fmt::format("edge {} ({}-{}) is not a side of any triangle", i + 1, a + 1, b + 1));
    listed[i] = e;
    mesh.edge_ref(e) = i < r.edge_refs.size() ? r.edge_refs[i] : 0;
    if (mesh.edge_ref(e) == kInterfaceRef) mesh.interface(e) = 1;
  }
  auto edge_list_item = [&](const BulkVector<std::int64_t>& items, const Locator& at, const char* section,
                            std::size_t k) {
    auto i = items[k];
    if (i < 0 || i >= std::int64_t(listed.size()))
      throw at.error(file, k,
                     fmt::format("{} entry {} refers to edge {}, expected an index into Edges 1..{}", section, k + 1,
                                 i + 1, listed.size()));
    return listed[std::size_t(i)];
  };
  for (std::size_t k = 0; k < r.ridges.size(); ++k) mesh.ridge(edge_list_item(r.ridges, r.ridge_at, "Ridges", k)) = 1;
  for (std::size_t k = 0; k < r.required_edges.size(); ++k)
    mesh.required(edge_list_item(r.required_edges, r.required_edge_at, "RequiredEdges", k)) = 1;
  auto vertex_list_item = [&](const BulkVector<std::int64_t>& items, const Locator& at, const char* section,
                              std::size_t k) {
    auto i = items[k];
    if (i < 0 || i >= nv)
      throw at.error(file, k,
                     fmt::format("{} entry {} refers to vertex {}, expected an index in 1..{}", section, k + 1, i + 1,
                                 nv));
    return VertexHandle(int(i));
  };
  for (std::size_t k = 0; k < r.corners.size(); ++k)
    mesh.corner(vertex_list_item(r.corners, r.corner_at, "Corners", k)) = 1;
  for (std::size_t k = 0; k < r.required_vertices.size(); ++k)
    mesh.required(vertex_list_item(r.required_vertices, r.required_vertex_at, "RequiredVertices", k)) = 1;

  // The interface: edges listed with ref 10, and edges between an inside and a non-inside face.
  if (mesh.has_regions()) {
    for_each_index(int(mesh.n_edges()), [&](int i) {
      const EdgeHandle e(i);
      if (mesh.is_boundary(e)) return;
      auto f0 = mesh.face_handle(mesh.halfedge_handle(e, 0));
      auto f1 = mesh.face_handle(mesh.halfedge_handle(e, 1));
      if (mesh.inside(f0) != mesh.inside(f1)) {
        mesh.interface(e) = 1;
        if (mesh.edge_ref(e) == 0) mesh.edge_ref(e) = kInterfaceRef;
      }
    });
  }

  // Last (after the more specific checks above): every vertex is a corner. A stray one would
  // stretch the bounding box, and with it every default size (relative to its diagonal), without
  // being part of the surface. Refused rather than dropped: dropping it would renumber the
  // vertices, and a .sol written for this mesh would no longer match.
  {
    const int isolated = first_where(int(nv), [&](int v) { return mesh.is_isolated(VertexHandle(v)); });
    if (isolated < nv) {
      const auto first = std::size_t(isolated);
      const int unused = reduce(
          int(nv), 0, [&](int v, int& count) { count += mesh.is_isolated(VertexHandle(v)); },
          [](int& count, int other) { count += other; });
      throw r.vertex_at.error(file, first,
                              fmt::format("vertex {} is not a corner of any triangle ({} such vertices): it would "
                                          "stretch the bounding box and so the default sizes; remove it",
                                          first + 1, unused));
    }
  }
  // Two boundary vertices at the same point: a vertex written twice, which cuts a closed surface
  // open along the faces that use the copy (a boundary where there is none). Boundary vertices only:
  // they are few, and a duplicate that opens nothing cannot lie anywhere else. MMG and CGAL take such
  // files: every set of vertices at one point is merged and the surface built again, with a warning
  // (the vertices are renumbered). When merging does not give a valid surface (two holes or two
  // fans that touch at a point: merged, the point would join separate fans), the vertices are kept
  // apart, as those tools do too: the surface touches itself there, which a warning says.
  {
    std::vector<int> boundary = collect<int>(int(nv), [&](int v, int& item) {
      item = v;
      return mesh.is_boundary(VertexHandle(v));
    });
    auto key = [&](int v) {
      const Vec3& p = mesh.point(VertexHandle(v));
      return std::array<double, 4>{p[0], p[1], p[2], double(v)};
    };
    std::sort(boundary.begin(), boundary.end(), [&](int a, int b) { return key(a) < key(b); });
    for (std::size_t k = 1; k < boundary.size(); ++k) {
      const int a = boundary[k - 1], b = boundary[k];
      if (mesh.point(VertexHandle(a)) != mesh.point(VertexHandle(b))) continue;
      const Vec3 p = mesh.point(VertexHandle(b));
      std::size_t merged = 0;
      MeshRecords joined = merge_coincident_vertices(r, merged);
      try {
        // Every return names `mesh`, so that it is built in the caller's object: OpenMesh's kernel
        // has no move constructor, and a `return` of another mesh would copy every array.
        mesh = build_mesh(std::move(joined), file, options);
        spdlog::warn("{}: {} vertices at the same point as an earlier one (vertex {} is vertex {}, ...) merged, as MMG "
                     "and CGAL do: the surface is closed there, and its vertices are renumbered",
                     file.string(), merged, b + 1, a + 1);
        return mesh;
      } catch (const InputError& e) {
        spdlog::warn("{}: vertices {} and {} are at the same point ({:.6g}, {:.6g}, {:.6g}), both on a boundary, and "
                     "merging them would not give a surface ({}): kept apart, the surface touches itself there",
                     file.string(), a + 1, b + 1, p[0], p[1], p[2], e.what());
        return mesh;
      }
    }
  }
  return mesh;
}

}  // namespace io_detail

SurfaceMesh mesh_from_arrays(std::span<const double> xyz, std::span<const std::int64_t> triangles,
                             std::span<const int> regions, const std::string& origin, const ReadOptions& options) {
  using namespace io_detail;
  if (xyz.size() % 3 || triangles.size() % 3)
    throw InputError(fmt::format("{}: {} coordinates and {} indices: 3 per vertex and per triangle expected", origin,
                                 xyz.size(), triangles.size()));
  if (!regions.empty() && regions.size() != triangles.size() / 3)
    throw InputError(fmt::format("{}: {} regions for {} triangles: one per triangle expected", origin, regions.size(),
                                 triangles.size() / 3));
  MeshRecords r;
  r.vertex_at = r.triangle_at = r.edge_at = Locator::none();
  r.corner_at = r.required_vertex_at = r.ridge_at = r.required_edge_at = Locator::none();
  r.points.resize(xyz.size() / 3);
  for (std::size_t i = 0; i < r.points.size(); ++i) r.points[i] = Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  r.vertex_refs.assign(r.points.size(), 0);
  // Arrays count from 0 (the builder's messages count from 1, as files do): what an array user
  // reads first is checked here, in the arrays' terms.
  for (std::size_t i = 0; i < r.points.size(); ++i)
    if (!std::isfinite(xyz[3 * i]) || !std::isfinite(xyz[3 * i + 1]) || !std::isfinite(xyz[3 * i + 2]))
      throw InputError(fmt::format("{}: vertices[{}] has a NaN or infinite coordinate", origin, i));
  const auto nv = static_cast<std::int64_t>(r.points.size());
  r.triangles.resize(triangles.size() / 3);
  for (std::size_t i = 0; i < r.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      if (triangles[3 * i + k] < 0 || triangles[3 * i + k] >= nv)
        throw InputError(fmt::format("{}: triangles[{}] refers to vertex {}, expected an index in 0..{}", origin, i,
                                     triangles[3 * i + k], nv - 1));
    r.triangles[i] = {triangles[3 * i], triangles[3 * i + 1], triangles[3 * i + 2]};
  }
  r.triangle_refs.assign(regions.begin(), regions.end());
  if (r.triangle_refs.empty()) r.triangle_refs.assign(r.triangles.size(), 0);
  return build_mesh(std::move(r), origin, options);
}

SurfaceMesh read_mesh(const std::filesystem::path& file, const ReadOptions& options) {
  using namespace io_detail;
  const std::string ext = extension_of(file);
  if (ext == ".mesh" || ext == ".meshb") return read_medit(file, options);
  if (ext == ".off") return read_off(file, options);
  if (ext == ".obj") return read_obj(file, options);
  if (ext == ".ply") return read_ply(file, options);
  if (ext == ".stl") return read_openmesh_format(file, options);
  if (ext == ".vtu") return read_vtu(file, nullptr, options);
  throw file_error(file, fmt::format("unknown mesh extension '{}' (expected .mesh, .meshb, .obj, .off, .ply, .stl or "
                                     ".vtu)",
                                     ext));
}

void write_mesh(const SurfaceMesh& mesh, const std::filesystem::path& file) {
  using namespace io_detail;
  const std::string ext = extension_of(file);
  if (ext == ".mesh" || ext == ".meshb") return write_medit(mesh, file, ext == ".meshb");
  if (ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl") return write_openmesh_format(mesh, file);
  if (ext == ".vtu") return write_vtu(mesh, file);
  throw file_error(file, fmt::format("unknown mesh extension '{}' (expected .mesh, .meshb, .obj, .off, .ply, .stl "
                                     "or .vtu)",
                                     ext));
}

}  // namespace bodyfit
