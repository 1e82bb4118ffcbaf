#pragma once
// The surface walker of the advection (private to advection.cpp and surface_walker.cpp): points of
// the surface as (face, barycentric coordinates), per-face records that make an edge crossing a few
// multiply-adds, and the walk that moves a point by a tangent displacement, unfolding it into the
// next face at each edge. The tracer of the characteristics (advection.cpp) is built on it.
#include <bodyfit/geometry.hpp>
#include <bodyfit/mesh.hpp>

#include <array>
#include <span>
#include <cstdint>
#include <vector>

namespace bodyfit::walker {

// ---- flat per-face data, built once per call ---------------------------------------------------

// The walk never leaves barycentric coordinates. A displacement inside a face is its increment of
// the three coordinates (Σ = 0); crossing an edge maps that increment linearly into the neighbour's
// coordinates through the unfolding about the edge, a map fixed by two numbers per edge: the
// coordinates, in this face, of the neighbour's far corner unfolded into this face's plane. A
// crossing is then a division, a few multiply-adds and one load of the next face's record, which
// fits one cache line. Velocities are stored the same way (the increment per unit time at each
// corner, in each incident face), so a sub-step needs no 3-D geometry at all.
struct alignas(64) Face {
  /// 1/α, α < 0 the coordinate for corner i of the neighbour's far corner unfolded across the edge
  /// opposite corner i.
  double unfold_far[3];
  /// The coordinate for corner (i + 1) % 3 of that unfolded far corner.
  double unfold_next[3];
  int neighbour[3];  ///< face across the edge opposite corner i, −1 on the boundary, kNotBuilt
  /// In the neighbour across edge i: bits 0–1 the slot of the corner opposite that edge, bits 2–3
  /// the slot of this face's corner (i + 1) % 3 (the third slot holds corner (i + 2) % 3).
  unsigned char across[3];
};
static_assert(sizeof(Face) == 64);

/// What a velocity evaluation reads, in one cache line: V at the corners as coordinate increments
/// per unit time (the third increment is minus the sum of the first two), and the squared edge
/// lengths in units of the face's mean edge length, which give a speed in cells per unit time:
/// |d|² = −(d₁d₂ℓ₀² + d₀d₂ℓ₁² + d₀d₁ℓ₂²) for an increment d (Σ dᵢ = 0).
struct alignas(64) FaceMotion {
  double rate[3][2];  ///< rate[j] = first two increments per unit time of V at corner j
  float edge2[3];     ///< (ℓ_k / mean edge length)², ℓ_k the edge opposite corner k (only sizes steps)
  /// The advect call that filled `rate`: a band call fills only the faces around the vertices where
  /// V is known, and a walk reaching another face is counted as having left the band.
  std::uint32_t epoch;
};
static_assert(sizeof(FaceMotion) == 64);

/// Coordinate increments of a tangent displacement (the three add up to zero).
struct Delta {
  double d[3] = {0, 0, 0};
};
inline Delta operator*(double s, const Delta& a) { return {{s * a.d[0], s * a.d[1], s * a.d[2]}}; }
inline Delta operator+(const Delta& a, const Delta& b) {
  return {{a.d[0] + b.d[0], a.d[1] + b.d[1], a.d[2] + b.d[2]}};
}

/// Face::neighbour of an edge whose other face exists but is not in a partial Surface.
constexpr int kNotBuilt = -2;

struct Surface {
  std::vector<Face> faces;
  std::vector<FaceMotion> motion;
  std::vector<std::array<int, 3>> corners;  ///< vertex indices of each face
  std::vector<Vec3> points;                 ///< vertex positions
  std::vector<int> vertex_face;          ///< one face incident to each vertex
  std::vector<signed char> vertex_slot;  ///< the vertex's corner slot in that face
  std::vector<int> vertex_order;         ///< vertices in Z-order: neighbours trace through the same faces
  std::vector<int> vertex_rank;          ///< position of each vertex in vertex_order
  std::vector<int> fan_start, fan;       ///< vertex → its faces (CSR, slots), built on first band call
  std::vector<float> face_length;        ///< mean edge length of each face (slot)
  double shortest_face = 0;              ///< the smallest of them (> 0 on a mesh that was read)
};

/// The walk's geometry (everything but the velocity), in Z-order. With `faces` (indices into the
/// mesh), only those: their edges towards the other faces are kNotBuilt, where a walk ends as
/// WalkEnd::left; the vertices' order is their index order (canonical meshes are in Z-order).
Surface build_surface(const SurfaceMesh& mesh, std::span<const int> faces = {});

/// V on the face in `slot` as coordinate increments per unit time at its corners.
inline void fill_motion(Surface& s, int slot, const VectorField& velocity, std::uint32_t epoch) {
  FaceMotion& m = s.motion[slot];
  const std::array<int, 3>& corner = s.corners[slot];
  const auto grad = p1_basis_gradients(s.points[corner[0]], s.points[corner[1]], s.points[corner[2]]);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 2; ++i) m.rate[j][i] = OpenMesh::dot(grad[i], velocity[corner[j]]);
  m.epoch = epoch;
}

/// The faces around each vertex (for the faces of a band).
void build_fans(Surface& s);

// ---- the walker --------------------------------------------------------------------------------

/// A point of the surface: a face and barycentric coordinates in it.
struct Location {
  int face = 0;
  double b[3] = {1, 0, 0};
};

/// left: reached an edge whose other face is not in the (partial) Surface.
enum class WalkEnd { arrived, boundary, left, stalled };

/// Crossings allowed in one walk before it is declared stalled (a sub-step crosses about one face;
/// turning around a vertex takes at most its valence in zero-length crossings).
constexpr int kMaxCrossings = 4096;

/// The increment d of face f carried across its edge opposite corner `exit` into the neighbour's
/// coordinates (the unfolding is an isometry, so this is the same displacement).
inline Delta carry(const Face& f, int exit, const Delta& d) {
  const int jo = f.across[exit] & 3, jn = f.across[exit] >> 2;
  Delta out;
  out.d[jo] = d.d[exit] * f.unfold_far[exit];
  out.d[jn] = d.d[(exit + 1) % 3] - f.unfold_next[exit] * out.d[jo];
  out.d[3 - jo - jn] = -(out.d[jo] + out.d[jn]);  // keeps Σ = 0 exactly
  return out;
}

/// One edge crossed by a walk: the face entered and the slot, in it, of the corner opposite the
/// edge; enough to carry an increment back (RK4 stages).
struct Crossed {
  int face;
  int far_slot;
};

/// a[i] for a variable i, by selects (the array stays in registers).
inline double pick(const double (&a)[3], int i) { return i == 0 ? a[0] : i == 1 ? a[1] : a[2]; }

/// Move `at` by the displacement d (coordinate increments in at.face). When `path` is given, the
/// crossed edges are appended to it.
///
/// The walk follows the segment from the current point to the target point, both in the current
/// face's coordinates (the target usually outside the face, some coordinates negative). At an
/// edge, the target is mapped into the neighbour's coordinates by the unfolding (an affine map of
/// two numbers), so the test "does the walk leave this face" only reads the target: the branch
/// does not wait for the division that places the crossing point.
[[gnu::always_inline]] inline WalkEnd walk(const Surface& s, Location& at, const Delta& d, std::vector<Crossed>* path) {
  int face = at.face;
  double b[3] = {at.b[0], at.b[1], at.b[2]};
  double e[3] = {b[0] + d.d[0], b[1] + d.d[1], b[2] + d.d[2]};
  for (int crossing = 0; crossing < kMaxCrossings; ++crossing) {
    // An overshoot below the rounding level is not a crossing: a path running along an edge (a
    // boundary edge in particular) stays on it instead of stepping out through rounding noise. The
    // target's coordinates grow with the displacement over the face size (10⁵ for a long step
    // through a 1e-6 face), and their rounding with them, amplified by the edge maps of a graded
    // mesh: the level is relative to their size (a path within 1e-11 of the step's length from an
    // edge runs along it).
    const double overshoot = -1e-11 * (1 + std::max({std::abs(e[0]), std::abs(e[1]), std::abs(e[2])}));
    const bool reaches[3] = {e[0] < overshoot, e[1] < overshoot, e[2] < overshoot};
    if (!reaches[0] && !reaches[1] && !reaches[2]) {  // the target is in this face
      at.face = face;
      at.b[0] = e[0] > 0 ? e[0] : 0.0;
      at.b[1] = e[1] > 0 ? e[1] : 0.0;
      at.b[2] = e[2] > 0 ? e[2] : 0.0;
      return WalkEnd::arrived;
    }
    const Face& f = s.faces[face];
    // First edge reached: the smallest t with b_i + t (e_i − b_i) = 0.
    int exit = -1;
    double t_exit = 1.0;
    for (int i = 0; i < 3; ++i) {
      if (!reaches[i]) continue;
      const double from = std::max(b[i], 0.0);
      const double t = from / (from - e[i]);
      // Ties (a path through a vertex): prefer an interior edge so the walk does not stop on the
      // boundary while the surface continues in the direction of travel.
      constexpr double tie = 1e-12;
      const bool earlier = exit < 0 || t < t_exit - tie;
      const bool tied_but_interior =
          exit >= 0 && t <= t_exit + tie && f.neighbour[exit] < 0 && f.neighbour[i] >= 0;
      if (earlier || tied_but_interior) {
        exit = i;
        t_exit = t;
      }
    }
    const int i1 = exit == 2 ? 0 : exit + 1, i2 = exit == 0 ? 2 : exit - 1;
    const double reached1 = std::max(pick(b, i1) + t_exit * (pick(e, i1) - pick(b, i1)), 0.0);
    const double reached2 = std::max(pick(b, i2) + t_exit * (pick(e, i2) - pick(b, i2)), 0.0);
    const int g = f.neighbour[exit];
    if (g < 0) {  // leaves the surface (or what was built of it): stop on the edge
      at.face = face;
      at.b[exit] = 0.0;
      at.b[i1] = reached1;
      at.b[i2] = reached2;
      return g == kNotBuilt ? WalkEnd::left : WalkEnd::boundary;
    }
    // Into the neighbour's slots: jo opposite the edge, jn this face's corner i1, jt its corner i2.
    // The permutation is done with selects, in registers: stores through a variable index would
    // be read back by wider loads that the store buffer cannot forward.
    const int jo = f.across[exit] & 3, jn = f.across[exit] >> 2;
    const double far = pick(e, exit) * f.unfold_far[exit];
    const double next = pick(e, i1) - f.unfold_next[exit] * far;
    const double third = 1.0 - far - next;
    for (int k = 0; k < 3; ++k) {
      e[k] = k == jo ? far : k == jn ? next : third;
      b[k] = k == jo ? 0.0 : k == jn ? reached1 : reached2;
    }
    if (path) path->push_back({g, jo});
    face = g;
  }
  at.face = face;
  for (int i = 0; i < 3; ++i) at.b[i] = b[i];
  return WalkEnd::stalled;
}

/// V at a location, as coordinate increments per unit time in its face.
inline Delta velocity_at(const Surface& s, const Location& at) {
  const FaceMotion& m = s.motion[at.face];
  Delta v;
  for (int i = 0; i < 2; ++i) v.d[i] = at.b[0] * m.rate[0][i] + at.b[1] * m.rate[1][i] + at.b[2] * m.rate[2][i];
  v.d[2] = -(v.d[0] + v.d[1]);
  return v;
}

/// Squared length of an increment of face f, in units of its mean edge length.
inline double cells2(const Surface& s, int face, const Delta& v) {
  const FaceMotion& m = s.motion[face];
  return std::max(0.0, -(v.d[1] * v.d[2] * double(m.edge2[0]) + v.d[0] * v.d[2] * double(m.edge2[1]) +
                         v.d[0] * v.d[1] * double(m.edge2[2])));
}

/// A vertex as a location: a corner of its face.
Location vertex_location(const Surface& s, int v);

Vec3 position(const Surface& s, const Location& at);

/// Walk `at` by a 3-D displacement, taken in the plane of its face (then unfolded as any walk).
WalkEnd walk_by(const Surface& s, Location& at, const Vec3& displacement);

}  // namespace bodyfit::walker
