#pragma once
// Projection onto fixed reference geometry: the input surface S (closest point on a triangle soup,
// or an exact sphere) and reference polylines (the input's interface curve, ridges, boundary).
// The remesher projects every new or moved vertex so that neither S nor the interface drifts.
#include <bodyfit/mesh.hpp>

#include <memory>
#include <mutex>
#include <vector>

namespace bodyfit {

namespace detail {
struct BoxTree;  // bounding-volume hierarchy of both projections (projection.cpp)
}

/// A point of S: position, unit normal of S there and the reference triangle (-1 when analytic).
struct SurfacePoint {
  Vec3 point{0, 0, 0};
  Vec3 normal{0, 0, 0};
  int face = -1;
};

class ReferenceSurface {
 public:
  /// Copy the triangles of `mesh` (non-deleted faces; face i of a garbage-collected mesh is
  /// reference triangle i). The search tree is built on the first query.
  explicit ReferenceSurface(const SurfaceMesh& mesh);
  ~ReferenceSurface();
  /// Exact sphere: the projection is c + r (p − c)/|p − c|.
  static std::shared_ptr<ReferenceSurface> sphere(const Vec3& center, double radius);

  /// Closest point of S to p. `hint` (a reference triangle near p, or -1) speeds up the search.
  SurfacePoint closest(const Vec3& p, int hint = -1) const;
  /// The distance from p to reference triangle `i` (infinite for an analytic S or no such
  /// triangle): an upper bound of p's distance to S, the one closest(p, i) starts its search from.
  double distance_to_triangle(const Vec3& p, int i) const;
  /// The least distance from p to the reference triangles sharing a side with triangle `i`
  /// (infinite for none): the next upper bounds of p's distance to S after distance_to_triangle.
  double distance_to_neighbours(const Vec3& p, int i) const;
  /// S's smooth unit normal at its closest point to p: S's vertex normals (area-weighted, as
  /// vertex_normal()) interpolated barycentrically there. A continuous field and one function of
  /// position, whatever mesh samples it; at a vertex of S it is S's vertex normal (a sphere: exact).
  Vec3 smooth_normal(const Vec3& p, int hint = -1) const { return smooth_normal(closest(p, hint)); }
  /// The same at a point closest() returned.
  Vec3 smooth_normal(const SurfacePoint& q) const;
  bool analytic() const { return is_sphere_; }
  /// Build the search tree now, with every thread. Otherwise the first query builds it, and the
  /// threads of a parallel sweep that query at the same time wait for it, idle.
  void prepare() const {
    if (!is_sphere_) ensure_tree();
  }
  /// Radius of the analytic sphere (0 for a triangle reference).
  double sphere_radius() const { return is_sphere_ ? radius_ : 0.0; }
  std::size_t n_triangles() const { return tri_.size(); }
  /// An upper estimate of S's normal curvature: the largest turn of the normal between two adjacent
  /// triangles per distance between their centroids (1/R on a fine tessellation of a sphere, 0 on a
  /// plane, large across a crease). A chord of length L between points of S then passes within
  /// L²·max_curvature()/8 of S.
  double max_curvature() const { return is_sphere_ ? 1.0 / radius_ : max_curvature_; }

 private:
  ReferenceSurface() = default;
  void ensure_tree() const;
  void ensure_neighbours() const;
  bool is_sphere_ = false;
  Vec3 center_{0, 0, 0};
  double radius_ = 1;
  double max_curvature_ = 0;
  std::vector<Vec3> points_;
  std::vector<std::array<int, 3>> tri_;
  std::vector<Vec3> normal_;
  std::vector<Vec3> vertex_normal_;
  mutable std::once_flag tree_once_;
  mutable std::unique_ptr<detail::BoxTree> tree_;
  /// Across each side of each triangle, −1 on the boundary; made on the first distance_to_neighbours().
  mutable std::vector<std::array<int, 3>> neighbour_;
  mutable std::once_flag neighbours_once_;
};

/// A set of segments, each with an integer label (e.g. the kind of curve); closest point among the
/// segments carrying a given label.
class ReferencePolyline {
 public:
  ReferencePolyline();
  ~ReferencePolyline();
  ReferencePolyline(ReferencePolyline&&) noexcept;
  ReferencePolyline& operator=(ReferencePolyline&&) noexcept;
  void add(const Vec3& a, const Vec3& b, int label);
  /// Closest point to p on the segments with `label`; returns p when there is none.
  Vec3 closest(const Vec3& p, int label) const;
  std::size_t size() const { return a_.size(); }
  /// Build the search tree now: closest() may then be called from several threads at once (until
  /// the next add() or smooth()). Otherwise the first query builds it.
  void prepare() const { ensure_tree(); }
  /// Replace the chords carrying `label` by a C¹ curve through the same vertices, so that points
  /// put on the curve (split midpoints, relocated vertices) stay on the smooth curve the polyline
  /// samples instead of falling inside it by the sagitta. Each segment becomes a cubic Hermite arc
  /// whose end tangents come from the neighbouring segment (Bessel's three-point tangent, exact to
  /// second order) where exactly two segments of `label` meet at a turning angle ≤ `corner_angle`
  /// (radians); at ends, corners and junctions the tangent is one-sided (the other end's tangent
  /// mirrored about the chord, or the chord itself). Vertices are matched by exact coordinates.
  /// Call after the last add() of that label.
  void smooth(int label, double corner_angle);
  /// Point at parameter t ∈ [0, 1] of segment i (on its Hermite arc when smoothed, else its chord).
  Vec3 point(std::size_t i, double t) const;

 private:
  void ensure_tree() const;
  /// Closest point to p on segment i (its arc when smoothed, else its chord).
  Vec3 closest_on(std::size_t i, const Vec3& p) const;
  std::vector<Vec3> a_, b_;
  std::vector<Vec3> da_, db_;  ///< Hermite end derivatives d/dt at a and b (chord b − a when not smoothed)
  std::vector<char> smooth_;
  std::vector<int> label_;
  mutable bool built_ = false;
  mutable std::unique_ptr<detail::BoxTree> tree_;
};

/// Closest point to p on the triangle abc.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
/// Closest point to p on the segment ab.
Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);

}  // namespace bodyfit
