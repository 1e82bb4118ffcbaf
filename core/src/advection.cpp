// Advection of a level set on a triangulated surface by the method of characteristics.
//
// Each vertex's characteristic is traced backwards, dX/dτ = −V(X), X(0) = x, over τ ∈ (0, T), and
// φ(T, x) = φ0(X(T)) is the P1 interpolation of φ0 at the foot. Points on the surface are (face,
// barycentric coordinates), never 3-D points off the surface. A displacement is applied by walking:
// inside a face the point moves along a straight line until it reaches an edge; the remaining
// displacement is then unfolded into the next face's plane (rotated about the shared edge) and the
// walk continues there. A path that reaches a vertex or runs along an edge is handled by the same
// rule (a zero-length step crosses to the next face), so no characteristic is ever dropped.
//
// Tangent vectors are moved between faces by the composed unfolding rotations: RK4 carries each
// stage's velocity back to the start face (the transpose), RK2 carries V(x) forward to the midpoint
// and continues walking from there.
//
// Faces are stored, and vertices traced, in Z-order so that neighbouring characteristics read
// neighbouring memory; each trace is independent, so the result does not depend on the threads.
#include <bodyfit/advection.hpp>

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace bodyfit {
namespace {

// ---- small fixed-size algebra (no allocation, fully inlined) -----------------------------------

struct V3 {
  double x = 0, y = 0, z = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double norm(V3 a) { return std::sqrt(dot(a, a)); }
inline V3 from(const Vec3& p) { return {p[0], p[1], p[2]}; }

/// Row-major 3×3 rotation.
struct M3 {
  double m[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  V3 apply(V3 v) const {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
            m[6] * v.x + m[7] * v.y + m[8] * v.z};
  }
  V3 apply_transposed(V3 v) const {
    return {m[0] * v.x + m[3] * v.y + m[6] * v.z, m[1] * v.x + m[4] * v.y + m[7] * v.z,
            m[2] * v.x + m[5] * v.y + m[8] * v.z};
  }
};

/// Rotation taking the orthonormal frame (e, a1, n1) to (e, a2, n2): R = Σ out_k ⊗ in_k, applied
/// on the left of the accumulated rotation (R ← R_new · R).
inline void compose_unfolding(M3& r, V3 e, V3 a1, V3 n1, V3 a2, V3 n2) {
  const double rn[9] = {e.x * e.x + a2.x * a1.x + n2.x * n1.x, e.x * e.y + a2.x * a1.y + n2.x * n1.y,
                        e.x * e.z + a2.x * a1.z + n2.x * n1.z, e.y * e.x + a2.y * a1.x + n2.y * n1.x,
                        e.y * e.y + a2.y * a1.y + n2.y * n1.y, e.y * e.z + a2.y * a1.z + n2.y * n1.z,
                        e.z * e.x + a2.z * a1.x + n2.z * n1.x, e.z * e.y + a2.z * a1.y + n2.z * n1.y,
                        e.z * e.z + a2.z * a1.z + n2.z * n1.z};
  M3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out.m[3 * i + j] = rn[3 * i] * r.m[j] + rn[3 * i + 1] * r.m[3 + j] + rn[3 * i + 2] * r.m[6 + j];
  r = out;
}

// ---- flat per-face data, built once per call ---------------------------------------------------

// The walk is bound by memory latency (each crossing loads the next face, each velocity evaluation
// its corners), so the record holds what the walk and the velocity evaluation read, and nothing
// else: three cache lines. The vertex indices, read once per characteristic, are kept apart.
struct alignas(64) Face {
  // What the walk reads comes first (the first 140 bytes), the corner velocities last.
  V3 grad[3];          ///< gradients of the P1 basis functions (in the face's plane)
  V3 normal;           ///< unit normal
  double altitude[3];  ///< 1/|∇λ_i|: the unfolding needs unit directions, without a square root
  int neighbour[3];    ///< face across the edge opposite corner i, −1 on the boundary
  /// In the neighbour across edge i: bits 0–1 the slot of the corner opposite that edge, bits 2–3
  /// the slot of this face's corner (i + 1) % 3 (the third slot holds corner (i + 2) % 3).
  unsigned char across[3];
  float size;        ///< mean edge length: sets the sub-step
  V3 velocity[3];    ///< V at the corners, projected on the face's plane (V is P1: project, then interpolate)
};
static_assert(sizeof(Face) == 256);  // 211 bytes of data


struct Surface {
  std::vector<Face> faces;
  std::vector<std::array<int, 3>> corners;  ///< vertex indices of each face
  std::vector<int> vertex_face;          ///< one face incident to each vertex
  std::vector<signed char> vertex_slot;  ///< the vertex's corner slot in that face
  std::vector<int> vertex_order;         ///< vertices in Z-order: neighbours trace through the same faces
};

/// Spreads the low 21 bits of x to every third bit (Morton interleaving).
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

/// Indices 0..n−1 sorted by the Z-order (Morton) code of point(i) in the box, ties by index, so the
/// order is deterministic. Walks from neighbouring vertices then touch neighbouring memory.
template <class PointOf>
std::vector<int> z_order(int n, const BoundingBox& box, PointOf point_of) {
  const Vec3 extent = box.max - box.min;
  const double scale = double((1 << 21) - 1);
  std::vector<std::pair<std::uint64_t, int>> keyed(n);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 8192), [&](const tbb::blocked_range<int>& range) {
    for (int i = range.begin(); i != range.end(); ++i) {
      const Vec3 p = point_of(i);
      std::uint64_t code = 0;
      for (int c = 0; c < 3; ++c) {
        const double t = extent[c] > 0 ? (p[c] - box.min[c]) / extent[c] : 0.0;
        code |= spread_bits(std::uint64_t(std::clamp(t, 0.0, 1.0) * scale)) << c;
      }
      keyed[i] = {code, i};
    }
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

Surface build_surface(const SurfaceMesh& mesh, const VectorField& velocity) {
  Surface s;
  const int nf = int(mesh.n_faces());
  const int nv = int(mesh.n_vertices());
  s.faces.resize(nf);
  s.corners.resize(nf);
  s.vertex_face.assign(nv, -1);
  s.vertex_slot.assign(nv, 0);
  // Faces are stored in Z-order of their centroids: a walk's next face is usually close in memory.
  const BoundingBox box = bounding_box(mesh);
  const std::vector<int> face_order = z_order(nf, box, [&](int fi) {
    Vec3 c(0, 0, 0);
    for (auto v : mesh.fv_range(FaceHandle(fi))) c += mesh.point(v);
    return c / 3.0;
  });
  std::vector<int> slot_of(nf);
  for (int i = 0; i < nf; ++i) slot_of[face_order[i]] = i;
  s.vertex_order = z_order(nv, box, [&](int vi) { return mesh.point(VertexHandle(vi)); });
  tbb::parallel_for(tbb::blocked_range<int>(0, nf, 4096), [&](const tbb::blocked_range<int>& range) {
    for (int fi = range.begin(); fi != range.end(); ++fi) {
      const FaceHandle fh(fi);
      Face& f = s.faces[slot_of[fi]];
      std::array<int, 3>& corner = s.corners[slot_of[fi]];
      V3 p[3];
      // Corner i is the target of halfedge h_i; the edge opposite corner i is that of h_{i+1}.
      HalfedgeHandle h[3];
      h[0] = mesh.halfedge_handle(fh);
      h[1] = mesh.next_halfedge_handle(h[0]);
      h[2] = mesh.next_halfedge_handle(h[1]);
      for (int i = 0; i < 3; ++i) {
        const VertexHandle v = mesh.to_vertex_handle(h[i]);
        corner[i] = v.idx();
        p[i] = from(mesh.point(v));
      }
      const auto g = p1_basis_gradients(mesh.point(VertexHandle(corner[0])), mesh.point(VertexHandle(corner[1])),
                                        mesh.point(VertexHandle(corner[2])));
      for (int i = 0; i < 3; ++i) {
        f.grad[i] = from(g[i]);
        const double len = norm(f.grad[i]);
        f.altitude[i] = len > 0 ? 1.0 / len : 0.0;
      }
      V3 n = cross(p[1] - p[0], p[2] - p[0]);
      const double nn = norm(n);
      const V3 normal = f.normal = nn > 0 ? (1.0 / nn) * n : V3{};
      for (int i = 0; i < 3; ++i) {
        const V3 v = from(velocity[corner[i]]);
        f.velocity[i] = v - dot(v, normal) * normal;
      }
      f.size = float((norm(p[1] - p[0]) + norm(p[2] - p[1]) + norm(p[0] - p[2])) / 3.0);
      for (int i = 0; i < 3; ++i) {
        // Edge opposite corner i joins corners i+1 and i+2: halfedge h_{i+2} runs from i+1 to i+2.
        const HalfedgeHandle opposite = mesh.opposite_halfedge_handle(h[(i + 2) % 3]);
        f.neighbour[i] = -1;
        f.across[i] = 0;
        if (mesh.is_boundary(opposite)) continue;
        const FaceHandle gh = mesh.face_handle(opposite);
        f.neighbour[i] = slot_of[gh.idx()];
        // Slots in g: the corner opposite the shared edge is next(opposite)'s target.
        HalfedgeHandle gh0 = mesh.halfedge_handle(gh);
        HalfedgeHandle gh_[3] = {gh0, mesh.next_halfedge_handle(gh0), HalfedgeHandle()};
        gh_[2] = mesh.next_halfedge_handle(gh_[1]);
        const int far = mesh.to_vertex_handle(mesh.next_halfedge_handle(opposite)).idx();
        int slot_far = 0, slot_next = 0;
        for (int j = 0; j < 3; ++j) {
          const int vj = mesh.to_vertex_handle(gh_[j]).idx();
          if (vj == far) slot_far = j;
          if (vj == corner[(i + 1) % 3]) slot_next = j;
        }
        f.across[i] = static_cast<unsigned char>(slot_far | (slot_next << 2));
      }
    }
  });
  // One incident face per vertex, chosen deterministically (smallest face index).
  for (int fi = 0; fi < nf; ++fi)
    for (int i = 0; i < 3; ++i) {
      const int v = s.corners[fi][i];
      if (s.vertex_face[v] < 0) {
        s.vertex_face[v] = fi;
        s.vertex_slot[v] = static_cast<signed char>(i);
      }
    }
  return s;
}

// ---- the walker --------------------------------------------------------------------------------

/// A point of the surface: a face and barycentric coordinates in it.
struct Location {
  int face = 0;
  double b[3] = {1, 0, 0};
};

enum class WalkEnd { arrived, boundary, stalled };

/// Crossings allowed in one walk before it is declared stalled (a sub-step crosses about one face;
/// turning around a vertex takes at most its valence in zero-length crossings).
constexpr int kMaxCrossings = 4096;

/// Move `at` by the tangent displacement d (expressed in the plane of at.face). When `rotation` is
/// given, the unfolding rotations of the crossed edges are composed into it.
WalkEnd walk(const Surface& s, Location& at, V3 d, M3* rotation) {
  // d need not be projected on the face's plane: the basis gradients ignore its normal part and the
  // unfolding rotations carry that part along as a normal part.
  for (int crossing = 0; crossing < kMaxCrossings; ++crossing) {
    const Face& f = s.faces[at.face];
    const double db[3] = {dot(f.grad[0], d), dot(f.grad[1], d), dot(f.grad[2], d)};
    // Coordinates reaching zero before the end of the displacement (b_i + db_i < 0). Most calls
    // end in the face they start in, and this test needs no division. An overshoot below the
    // rounding level is not a crossing: a path running along an edge (a boundary edge in
    // particular) stays on it instead of stepping out through rounding noise.
    constexpr double overshoot = -1e-13;
    const bool reaches[3] = {at.b[0] + db[0] < overshoot, at.b[1] + db[1] < overshoot, at.b[2] + db[2] < overshoot};
    if (!reaches[0] && !reaches[1] && !reaches[2]) {  // stays in this face
      for (int i = 0; i < 3; ++i) at.b[i] = std::max(at.b[i] + db[i], 0.0);
      return WalkEnd::arrived;
    }
    // First edge reached: the smallest t with b_i + t db_i = 0.
    int exit = -1;
    double t_exit = 1.0;
    for (int i = 0; i < 3; ++i) {
      if (!reaches[i]) continue;
      const double t = std::max(at.b[i], 0.0) / -db[i];
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
    double b[3];
    for (int i = 0; i < 3; ++i) b[i] = i == exit ? 0.0 : std::max(at.b[i] + t_exit * db[i], 0.0);
    const int i1 = (exit + 1) % 3, i2 = (exit + 2) % 3;
    const int g = f.neighbour[exit];
    if (g < 0) {  // leaves the surface: stop on the boundary edge
      for (int i = 0; i < 3; ++i) at.b[i] = b[i];
      return WalkEnd::boundary;
    }
    d = (1.0 - t_exit) * d;
    const Face& fg = s.faces[g];
    // Unfold about the shared edge: the frame (e, u1, n1) of f maps to (e, u2, n2) of g, where u1 is
    // the unit direction leaving f across the edge (−∇λ_exit normalised) and u2 the one entering g
    // (∇λ of g's corner opposite the edge, normalised); e = u1 × n1 is the edge direction.
    const int jo = f.across[exit] & 3, jn = f.across[exit] >> 2;
    const V3 n1 = f.normal, n2 = fg.normal;
    const V3 u1 = (-f.altitude[exit]) * f.grad[exit];
    const V3 u2 = fg.altitude[jo] * fg.grad[jo];
    const V3 e = cross(u1, n1);
    d = dot(d, e) * e + dot(d, u1) * u2 + dot(d, n1) * n2;
    if (rotation) compose_unfolding(*rotation, e, u1, n1, u2, n2);
    at.face = g;
    at.b[jo] = 0.0;
    at.b[jn] = b[i1];
    at.b[3 - jo - jn] = b[i2];
  }
  return WalkEnd::stalled;
}

/// V at a location, projected onto the face's plane.
inline V3 velocity_at(const Surface& s, const Location& at) {
  const Face& f = s.faces[at.face];
  return at.b[0] * f.velocity[0] + at.b[1] * f.velocity[1] + at.b[2] * f.velocity[2];
}

struct TraceResult {
  Location foot;
  std::size_t substeps = 0;
  bool boundary = false;
  bool stalled = false;
};

/// Trace the characteristic through `start` backwards over a time T.
TraceResult trace(const Surface& s, Location start, double T,
                  const AdvectionOptions& opt) {
  TraceResult r;
  Location x = start;
  const int outer = std::max(1, opt.steps);
  const double outer_dt = T / outer;
  auto stage = [&](const Location& from, V3 d, V3& k) -> bool {
    // V at the point reached from `from` by walking d, carried back into from's plane.
    Location y = from;
    M3 rot;
    if (walk(s, y, d, &rot) == WalkEnd::stalled) return false;
    k = rot.apply_transposed(velocity_at(s, y));
    return true;
  };
  for (int o = 0; o < outer; ++o) {
    double remaining = outer_dt;
    double dt = 0;  // kept from one sub-step to the next while it still fits (no square root, no division)
    while (remaining > 0) {
      const V3 k1 = velocity_at(s, x);
      const double speed2 = dot(k1, k1);
      const double reach = opt.max_cells_per_substep * s.faces[x.face].size;
      if (dt == 0 || speed2 * dt * dt > 1.5625 * reach * reach) {  // (1.25 reach)²
        // Equal sub-steps over what remains, each crossing about `reach`.
        dt = speed2 * remaining * remaining > reach * reach ? remaining / std::ceil(std::sqrt(speed2) * remaining / reach)
                                                            : remaining;
      }
      if (dt >= remaining * (1 - 1e-12)) dt = remaining;  // no sliver of a last step
      remaining = dt == remaining ? 0.0 : remaining - dt;
      ++r.substeps;
      if (opt.rk_order == 4) {
        V3 k2, k3, k4;
        if (!stage(x, (-0.5 * dt) * k1, k2) || !stage(x, (-0.5 * dt) * k2, k3) || !stage(x, (-dt) * k3, k4)) {
          r.stalled = true;
          break;
        }
        const WalkEnd end = walk(s, x, (-dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4), nullptr);
        if (end != WalkEnd::arrived) {
          (end == WalkEnd::boundary ? r.boundary : r.stalled) = true;
          break;
        }
      } else {
        // Midpoint rule, x ← x − dt·V(x − dt/2·V(x)). The walk goes on from the midpoint y rather
        // than restarting from x: the remaining displacement, −dt·V(y) + dt/2·V(x), is expressed in
        // y's face through the unfolding rotation of the first half. Where both walks would cross
        // the same faces the end point is the same, and the walked length drops from 1.5 to 1.
        M3 rotation;
        WalkEnd end = walk(s, x, (-0.5 * dt) * k1, &rotation);
        if (end == WalkEnd::arrived) {
          const V3 k2 = velocity_at(s, x);
          end = walk(s, x, (-dt) * k2 + (0.5 * dt) * rotation.apply(k1), nullptr);
        }
        if (end != WalkEnd::arrived) {
          (end == WalkEnd::boundary ? r.boundary : r.stalled) = true;
          break;
        }
      }
    }
    if (r.boundary || r.stalled) break;
  }
  r.foot = x;
  return r;
}

void check_inputs(const SurfaceMesh& mesh, std::size_t phi_size, std::size_t other_size, double T,
                  const AdvectionOptions& options, const char* what) {
  if (phi_size != mesh.n_vertices())
    throw InputError("advect: phi has " + std::to_string(phi_size) + " values, the mesh " +
                     std::to_string(mesh.n_vertices()) + " vertices");
  if (other_size != mesh.n_vertices())
    throw InputError(std::string("advect: ") + what + " has " + std::to_string(other_size) + " values, the mesh " +
                     std::to_string(mesh.n_vertices()) + " vertices");
  if (!std::isfinite(T) || T < 0) throw InputError("advect: the time must be finite and non-negative");
  if (options.rk_order != 2 && options.rk_order != 4) throw InputError("advect: rk_order must be 2 or 4");
  if (!(options.max_cells_per_substep > 0)) throw InputError("advect: max_cells_per_substep must be positive");
  if (options.steps < 1) throw InputError("advect: steps must be at least 1");
}

}  // namespace

ScalarField advect(const SurfaceMesh& mesh, const ScalarField& phi, const VectorField& velocity, double T,
                   const AdvectionOptions& options, AdvectionReport* report) {
  check_inputs(mesh, phi.size(), velocity.size(), T, options, "the velocity");
  const Surface s = build_surface(mesh, velocity);

  const int nv = int(mesh.n_vertices());
  ScalarField out(nv, 0.0);
  VectorField gradients;
  std::vector<Vec3> points;
  if (options.gradient_correction) {
    gradients = vertex_gradients(mesh, phi);
    points.resize(std::size_t(nv));
    for (auto vh : mesh.vertices()) points[std::size_t(vh.idx())] = mesh.point(vh);
  }
  std::atomic<std::size_t> substeps{0}, boundary{0}, lost{0}, traced{0};
  tbb::parallel_for(tbb::blocked_range<int>(0, nv, 256), [&](const tbb::blocked_range<int>& range) {
    std::size_t local_sub = 0, local_boundary = 0, local_lost = 0, local_traced = 0;
    for (int k = range.begin(); k != range.end(); ++k) {
      const int v = s.vertex_order[k];
      const int fi = s.vertex_face[v];
      if (fi < 0) {  // isolated vertex: nothing carries it
        out[v] = phi[v];
        continue;
      }
      Location start;
      start.face = fi;
      start.b[0] = start.b[1] = start.b[2] = 0.0;
      start.b[s.vertex_slot[v]] = 1.0;
      const TraceResult r = trace(s, start, T, options);
      const std::array<int, 3>& c = s.corners[r.foot.face];
      double value = r.foot.b[0] * phi[c[0]] + r.foot.b[1] * phi[c[1]] + r.foot.b[2] * phi[c[2]];
      if (options.gradient_correction) {
        const Vec3 x = r.foot.b[0] * points[c[0]] + r.foot.b[1] * points[c[1]] + r.foot.b[2] * points[c[2]];
        double taylor = 0, lo = phi[c[0]], hi = phi[c[0]];
        for (int j = 0; j < 3; ++j) {
          taylor += r.foot.b[j] * (phi[c[j]] + OpenMesh::dot(gradients[c[j]], x - points[c[j]]));
          lo = std::min(lo, phi[c[j]]);
          hi = std::max(hi, phi[c[j]]);
        }
        value = std::clamp(0.5 * (value + taylor), lo, hi);
      }
      out[v] = value;
      ++local_traced;
      local_sub += r.substeps;
      local_boundary += r.boundary;
      local_lost += r.stalled;
    }
    substeps += local_sub;
    boundary += local_boundary;
    lost += local_lost;
    traced += local_traced;
  });
  if (report) {
    report->traced = traced;
    report->substeps = substeps;
    report->hit_boundary = boundary;
    report->lost = lost;
  }
  return out;
}

ScalarField advect_normal(const SurfaceMesh& mesh, const ScalarField& phi, const ScalarField& normal_speed,
                          double T, const AdvectionOptions& options, AdvectionReport* report) {
  check_inputs(mesh, phi.size(), normal_speed.size(), T, options, "the normal speed");
  const VectorField grad = vertex_gradients(mesh, phi);
  // A gradient this much smaller than the largest one is a flat spot of φ: no direction, V = 0.
  double largest = 0;
  for (const Vec3& g : grad) largest = std::max(largest, g.norm());
  const double vanishing = 1e-12 * largest;
  VectorField velocity(grad.size(), Vec3(0, 0, 0));
  for (std::size_t i = 0; i < grad.size(); ++i) {
    const double len = grad[i].norm();
    if (len > vanishing) velocity[i] = (normal_speed[i] / len) * grad[i];
  }
  return advect(mesh, phi, velocity, T, options, report);
}

}  // namespace bodyfit
