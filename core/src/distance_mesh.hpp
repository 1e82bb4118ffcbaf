#pragma once
// The surface as the fast marching reads it (distance.cpp): the corners and neighbours of each face,
// the fan of triangles around each vertex, every obtuse corner split by Kimmel–Sethian unfolding.
// Built where the march goes: a narrow band on a large mesh reads a small part of it.
#include <bodyfit/mesh.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace bodyfit::distance_detail {

/// Gram data of a corner: the triangle (x; a, b) seen from x, with ea = a − x, eb = b − x.
struct CornerGeometry {
  double aa = 0, bb = 0, ab = 0;  ///< |ea|², |eb|², ea·eb
};

inline CornerGeometry corner_geometry(const Vec3& ea, const Vec3& eb) { return {ea.sqrnorm(), eb.sqrnorm(), ea | eb}; }

/// For an obtuse corner: the vertex r found by unfolding the faces beyond the opposite edge that
/// splits the angle into two acute ones, with the geometry of the virtual triangles (x; a, r) and
/// (x; r, b).
struct ObtuseSplit {
  int corner = -1;  ///< 3f + c of the obtuse corner
  int vertex = -1;  ///< r
  CornerGeometry first, second;
};

/// One triangle of the fan around a vertex v: its two other vertices in order (v, a, b), the corner
/// 3f + c of v, and which of the corners at a and b are obtuse (bits 1 and 2).
struct FanTriangle {
  int a = 0, b = 0;
  int corner = 0;
  std::uint8_t obtuse = 0;
};

/// Where the fan of a vertex lies in FlatMesh's fan storage.
struct FanRange {
  int begin = 0, end = 0;
};

/// The surface as flat arrays, filled on first use: a face's corners and the faces across its
/// edges; then its obtuse corners and their splits; a vertex's fan once every face around it is
/// classified. The values are the same whatever order they are asked in (a fan lists its triangles
/// in corner order). Not thread-safe: one march at a time.
class FlatMesh {
 public:
  explicit FlatMesh(const SurfaceMesh& mesh);

  std::size_t nv() const { return nv_; }
  std::size_t nf() const { return nf_; }
  const Vec3& point(int v) const { return points_[v]; }

  /// Corner k = 3f + c: its vertex, and the face across the edge opposite it (−1 on the boundary).
  int corner_vertex(int k) const { return topology(k / 3).vertex[k % 3]; }
  int across(int k) const { return topology(k / 3).across[k % 3]; }
  /// Corner k's split (an index for split()), −2 when obtuse without a split, −1 when not obtuse.
  int obtuse(int k) const { return classified(k / 3).obtuse[k % 3]; }
  /// The fan of v: triangles fan_triangle(j) for j in [begin, end). Read by index: building another
  /// fan may move the storage.
  FanRange fan(int v) const;
  FanTriangle fan_triangle(int j) const { return fan_[std::size_t(j)]; }
  /// Split i (by value: classifying another face may move the storage).
  ObtuseSplit split(int i) const { return splits_[std::size_t(i)]; }
  /// The splits whose unfolded vertex is r, as a list: first_split_at(r), then next_split(i), −1 at the end.
  int first_split_at(int r) const { return split_head_[std::size_t(r)]; }
  int next_split(int i) const { return split_next_[std::size_t(i)]; }

  /// Every face and fan at once, the independent parts in parallel: for a march over the whole surface.
  void build_all() const;

 private:
  struct Face {
    int vertex[3];
    int across[3];
    int obtuse[3];
  };
  const Face& topology(int f) const {
    if (face_state_[std::size_t(f)] == 0) build_topology(f);
    return faces_[std::size_t(f)];
  }
  const Face& classified(int f) const {
    if (face_state_[std::size_t(f)] < 2) classify(f);
    return faces_[std::size_t(f)];
  }
  void build_topology(int f) const;
  void classify(int f) const;
  void find_obtuse(int f) const;
  void split_obtuse_corner(int k) const;
  void build_fan(int v) const;

  const SurfaceMesh& mesh_;
  std::size_t nv_ = 0, nf_ = 0;
  const Vec3* points_ = nullptr;
  // Lazily filled caches, hence mutable.
  mutable std::unique_ptr<Face[]> faces_;               // uninitialised until face_state_ says
  mutable std::vector<std::uint8_t> face_state_;        // 0 nothing, 1 topology, 2 classified
  mutable std::vector<ObtuseSplit> splits_;
  mutable std::vector<int> split_head_, split_tail_, split_next_;
  mutable std::vector<FanRange> fan_range_;            // begin = −1: not built
  mutable std::vector<FanTriangle> fan_;
};

/// Discrete Gaussian curvature at vertex v: angle defect over a third of the incident area
/// (0 on the boundary, where the defect measures the boundary's turning instead).
double gaussian_curvature(const FlatMesh& m, int v);

}  // namespace bodyfit::distance_detail
