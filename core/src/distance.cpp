// Signed geodesic distance on a triangulated surface: exact initialisation next to the zero set of
// the P1 level set, then fast marching (Kimmel–Sethian triangle update, obtuse angles split by
// unfolding) over flat arrays.
#include "distance_seeds.hpp"

#include <bodyfit/distance.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <queue>
#include <utility>
#include <vector>

namespace bodyfit {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using namespace distance_detail;

/// Planar-front update of x from the known values da at a and db at b (Kimmel–Sethian): the value
/// t at x such that the linear interpolant of (t, da, db) has unit gradient and its characteristic
/// reaches x from inside the angle (a, x, b); +infinity when there is no such t (the caller then
/// uses the edges). A causal t never exceeds the edge values da + |ea|, db + |eb| (unit gradient).
double triangle_update(const CornerGeometry& g, double da, double db) {
  const double det = g.aa * g.bb - g.ab * g.ab;
  // Q⁻¹ = [[bb, −ab], [−ab, aa]] / det. Solve (1ᵀQ⁻¹1) t² − 2 (1ᵀQ⁻¹D) t + DᵀQ⁻¹D − 1 = 0.
  const double qa = g.aa + g.bb - 2 * g.ab;  // |a − b|², times 1/det omitted everywhere
  const double qb = da * (g.bb - g.ab) + db * (g.aa - g.ab);
  const double qc = da * da * g.bb - 2 * da * db * g.ab + db * db * g.aa - det;
  const double disc = qb * qb - qa * qc;
  if (det <= 0 || disc < 0 || qa <= 0) return kInf;
  const double t = (qb + std::sqrt(disc)) / qa;
  // Causality: −∇d = α ea + β eb with α, β ≥ 0, i.e. Q⁻¹(D − t·1) ≤ 0.
  const double ua = da - t, ub = db - t;
  return g.bb * ua - g.ab * ub <= 0 && g.aa * ub - g.ab * ua <= 0 ? t : kInf;
}

/// A tentative value with the geodesic curvature κ of the front there: κ > 0 when the front
/// diverges (its centre of curvature lies behind it), κ < 0 when it converges, 0 when straight.
struct FrontValue {
  double d = kInf;
  double kappa = 0;
};

/// Curvature of the front after it travels `step` from where it was κ, on a surface of Gaussian
/// curvature K: the Riccati equation of parallel curves, dκ/ds = −κ² − K, by Strang splitting —
/// half the K term, the exact flat growth κ/(1 + κs), the other half — second order in the step.
/// (Taking the K term at first order left the distance from a great circle of a 0.1-edge sphere
/// 7 % further off; the exact tan/tanh solution is no better than this and costs more.)
double carried_curvature(double kappa, double step, double gauss) {
  const double half = kappa - 0.5 * gauss * step;
  const double grown = 1 + half * step;
  return (grown > 1e-12 ? half / grown : half) - 0.5 * gauss * step;
}

/// The part of carried_curvature due to K alone (what the exact flat growth κ/(1 + κs) misses).
double gaussian_part(double kappa, double step, double gauss) {
  const double grown = 1 + kappa * step;
  return carried_curvature(kappa, step, gauss) - (grown > 1e-12 ? kappa / grown : kappa);
}

/// Update of x from a and b whose front is a circle rather than a line: in the plane of the
/// triangle, the centre S lies at distances 1/κ − d + d_a from a and 1/κ − d + d_b from b (the radius
/// grows with d; 1/κ − d averaged over a and b), behind the edge ab for a diverging front and beyond
/// it for a converging one, and d_x follows from |x − S|; the curvature at x is carried by the
/// Riccati equation with the Gaussian curvature K of the surface there. On a flat surface this is
/// exact for the distance to a circle, where the planar update errs by O(h²κ) at every step (which
/// accumulates to O(h) over a march). Falls back to the planar update when the front is almost
/// straight or the data are inconsistent; gives no value (d = ∞) when the characteristic from S
/// does not reach x through ab.
FrontValue front_update(const CornerGeometry& g, double da, double db, double ka, double kb, double gauss) {
  FrontValue out;
  const double mean_d = 0.5 * (da + db), mean_k = 0.5 * (ka + kb);
  auto planar = [&] {
    out.d = triangle_update(g, da, db);
    out.kappa = std::isfinite(out.d) ? carried_curvature(mean_k, out.d - mean_d, gauss) : mean_k;
    return out;
  };
  const double longest = std::sqrt(std::max(g.aa, g.bb));
  // Fronts curving by less than 1e-4 per edge length, or of mixed sense, are straight here.
  if (std::abs(ka) * longest < 1e-4 || std::abs(kb) * longest < 1e-4 || ka * kb <= 0) return planar();
  const double R = 0.5 * ((1 / ka - da) + (1 / kb - db));  // signed radius minus distance
  const double signed_a = da + R, signed_b = db + R;
  const bool diverging = signed_a > 0 && signed_b > 0;
  if (!diverging && !(signed_a < 0 && signed_b < 0)) return planar();
  // x at the origin, a on the first axis, b above it: x lies on the left of the line a → b.
  const double la = std::sqrt(g.aa);
  const double ax = la, bx = g.ab / la, by = std::sqrt(std::max(g.bb - bx * bx, 0.0));
  const double ex = bx - ax, ey = by, length = std::hypot(ex, ey);
  if (!(by > 0) || !(length > 0)) return planar();
  const double ux = ex / length, uy = ey / length;  // along a → b; its left normal is (−uy, ux)
  const double rad_a = std::abs(signed_a), rad_b = std::abs(signed_b);
  const double along = ((rad_a - rad_b) * (rad_a + rad_b) + length * length) / (2 * length);
  const double across2 = (rad_a - along) * (rad_a + along);
  if (across2 < 0) return planar();
  // Behind the edge (right of a → b, away from x) when diverging, on x's side when converging.
  const double across = diverging ? -std::sqrt(across2) : std::sqrt(across2);
  const double sx = ax + along * ux - across * uy, sy = along * uy + across * ux;
  const double to_x = std::hypot(sx, sy);
  // The characteristic is the line through S and x: it must cross the edge ab at a point P before
  // x (between S and x when diverging, beyond x seen from S when converging).
  const double cross_s = ex * sy - ey * sx, cross_a = -ey * ax;  // e × S and e × A (A = (ax, 0))
  if (cross_s == 0) return planar();
  const double keep = cross_a / cross_s;  // P = keep · S
  const double px = keep * sx, py = keep * sy;
  const double mu = ((px - ax) * ux + py * uy) / length;
  // Not through this edge: another triangle of x carries the characteristic (as the planar
  // update's own causality test would say), so no value from this one.
  if (mu < 0 || mu > 1 || (diverging ? !(keep > 0 && keep < 1) : !(keep < 0))) return out;
  // |x − S| − |a − S| without cancellation: (|S|² − |S − A|²) / (|S| + |S − A|) = (2 S·A − |A|²) / (…).
  const double grow_a = (2 * sx * ax - ax * ax) / (to_x + rad_a);
  const double grow_b = (2 * (sx * bx + sy * by) - g.bb) / (to_x + rad_b);
  const double value = diverging ? 0.5 * (da + grow_a + db + grow_b) : 0.5 * (da - grow_a + db - grow_b);
  if (!(value >= std::max(da, db)) || !(to_x > 0)) return planar();
  out.d = value;
  // The circle through x gives the flat growth exactly; K adds its share of the Riccati solution.
  out.kappa = (diverging ? 1 / to_x : -1 / to_x) + gaussian_part(mean_k, value - mean_d, gauss);
  return out;
}

double point_segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 e = b - a;
  const double len2 = e.sqrnorm();
  double t = len2 > 0 ? ((p - a) | e) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (p - (a + e * t)).norm();
}

/// Distance from p to the arc x(t), t ∈ [0, 1], from a to b whose curvature vector (towards the
/// centre) goes linearly from ka to kb: x'' = |b − a|²·((1−t)·ka + t·kb) departs from the chord by
/// −|b − a|²·t(1−t)·((2−t)·ka + (1+t)·kb)/6, towards the convex side (κL²/8 at the middle for a
/// circle). Evaluated at the foot of p on the chord, which moves the nearest point by O(h²κ) along
/// the curve and changes the distance only at O(h³).
double point_arc_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& ka, const Vec3& kb) {
  const Vec3 e = b - a;
  const double len2 = e.sqrnorm();
  double t = len2 > 0 ? ((p - a) | e) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const Vec3 bulge = (ka * (2 - t) + kb * (1 + t)) * (-len2 * t * (1 - t) / 6);
  return (p - (a + e * t) - bulge).norm();
}

/// Signed curvature of the interface arc (ka, kb) at the foot of p, seen from p: positive when p
/// lies on the convex side (the fronts around p diverge), negative on the concave side.
double curvature_seen_from(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& ka, const Vec3& kb) {
  const Vec3 e = b - a;
  const double len2 = e.sqrnorm();
  double t = len2 > 0 ? ((p - a) | e) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const Vec3 away = p - (a + e * t);
  const double length = away.norm();
  return length > 0 ? -((ka * (1 - t) + kb * t) | away) / length : 0.0;
}

constexpr int kNearRings = 3;
constexpr double kNearRadius = 2.5;

using HeapEntry = std::pair<double, int>;
using MinHeap = std::priority_queue<HeapEntry, std::vector<HeapEntry>, std::greater<>>;

/// The march's per-vertex arrays, kept between the calls of a DistanceSolver so that a narrow-band
/// call touches only the band: `touched` lists the vertices whose entries differ from the initial
/// (dist ∞, κ 0, state 0), and `reset` restores only those.
struct MarchWorkspace {
  std::vector<double> dist, kappa;
  std::vector<std::uint8_t> state;  ///< 0 far, 1 tentative, 2 fixed by the initialisation, 3 accepted
  std::vector<int> stamp;           ///< ring marks: stamp_base + seed face index
  int stamp_base = 0;
  std::vector<int> touched;

  void prepare(std::size_t nv, std::size_t seed_faces) {
    if (dist.size() != nv) {
      dist.assign(nv, kInf);
      kappa.assign(nv, 0.0);
      state.assign(nv, 0);
      stamp.assign(nv, -1);
      stamp_base = 0;
      touched.clear();
    }
    for (int v : touched) dist[v] = kInf, kappa[v] = 0, state[v] = 0;
    touched.clear();
    if (stamp_base > std::numeric_limits<int>::max() - int(seed_faces) - 1) {
      std::fill(stamp.begin(), stamp.end(), -1);
      stamp_base = 0;
    }
  }
  void set(int v, double d) {
    if (dist[v] == kInf && state[v] == 0) touched.push_back(v);
    dist[v] = d;
  }
};

/// One march: the exact initialisation next to the seeds, then fast marching up to
/// options.narrow_band, into the workspace (w.dist / w.state, accepted = 3, for w.touched).
class FastMarch {
 public:
  FastMarch(const FlatMesh& m, const Seeds& seeds, const DistanceOptions& options, MarchWorkspace& w)
      : m_(m), seeds_(seeds), options_(options), w_(w), dist_(w.dist), kappa_(w.kappa), state_(w.state),
        // The front's geodesic curvature at each vertex (FrontValue), carried from the interface's
        // when it is curved and front_curvature is on; otherwise fronts are straight (the planar update).
        track_(options.front_curvature && !seeds.bends.empty()),
        gauss_(track_ ? m.nv() : 0, kUnknown) {}

  /// Exact initialisation. Every vertex of a seed face is fixed to its Euclidean distance to the
  /// segments of the seed faces around it (those with a vertex in its 1-ring); on a smooth surface
  /// this differs from the geodesic distance by O(h³), far below the O(h²) of the P1 zero set. The
  /// vertices up to kNearRings rings further get the same direct distance: final where it is below
  /// kNearRadius shortest edges (every interface point that close lies in a seed face within those
  /// rings), tentative beyond. This keeps the near field second-order accurate.
  void initialise() {
    std::vector<int>& stamp = w_.stamp;
    const int base = w_.stamp_base;
    w_.stamp_base += int(seeds_.faces.size());
    std::vector<int> ring;
    for (std::size_t i = 0; i < seeds_.faces.size(); ++i) {
      const int mark = base + int(i);
      ring.clear();
      for (int c = 0; c < 3; ++c) {
        const int u = m_.corner_vertex(3 * seeds_.faces[i] + c);
        stamp[u] = mark;
        ring.push_back(u);
        if (state_[u] == 0 && dist_[u] == kInf) w_.touched.push_back(u);
        state_[u] = 2;
      }
      for (int depth = 0, begin = 0; depth < kNearRings; ++depth) {
        const int end = int(ring.size());
        for (int r = begin; r < end; ++r) {
          const FanRange fan = m_.fan(ring[r]);
          for (int j = fan.begin; j < fan.end; ++j) {
            const FanTriangle t = m_.fan_triangle(j);
            for (int x : {t.a, t.b})
              if (stamp[x] != mark) {
                stamp[x] = mark;
                ring.push_back(x);
              }
          }
        }
        begin = end;
      }
      for (int x : ring) set_nearest(x, i);
    }
  }

  /// Fast marching from every vertex given a value so far, up to options.narrow_band.
  void run(DistanceReport& report) {
    MinHeap heap = initial_heap(report);
    while (!heap.empty()) {
      const auto [d, v] = heap.top();
      heap.pop();
      if (state_[v] == 3 || d > dist_[v]) continue;
      if (d > options_.narrow_band) break;
      if (state_[v] == 1) ++report.marched;
      state_[v] = 3;
      accept(v, d, heap);
    }
  }

 private:
  bool known(int v) const { return state_[v] >= 2; }

  /// x's distance to the segments of seed face i when it is the nearest so far.
  void set_nearest(int x, std::size_t i) {
    const Vec3& p = m_.point(x);
    double best = dist_[x];
    int best_segment = -1;
    for (int k = seeds_.seg_start[i]; k < seeds_.seg_start[i + 1]; ++k) {
      const auto& [a, b] = seeds_.segments[k];
      const double value = seeds_.bends.empty()
                               ? point_segment_distance(p, a, b)
                               : point_arc_distance(p, a, b, seeds_.bends[k].first, seeds_.bends[k].second);
      // On a tie (an interface vertex is also the end of its edges) an edge gives the curvature.
      const bool point_so_far =
          best_segment >= 0 && seeds_.segments[best_segment].first == seeds_.segments[best_segment].second;
      if (value < best || (value == best && point_so_far && a != b)) {
        best = value;
        best_segment = k;
      }
    }
    if (best_segment < 0) return;  // an earlier seed face was closer
    w_.set(x, best);
    if (track_) {
      const auto& [a, b] = seeds_.segments[best_segment];
      const auto& [ka, kb] = seeds_.bends[best_segment];
      kappa_[x] = a == b ? 0.0 : carried_curvature(curvature_seen_from(p, a, b, ka, kb), best, gauss(x));
    }
  }

  /// Every vertex given a value so far (in touched), in index order so that the march does not
  /// depend on the order the seeds came in.
  MinHeap initial_heap(DistanceReport& report) {
    for (int v : seeds_.zeros) w_.set(v, 0.0);
    std::vector<int> initial = w_.touched;
    std::sort(initial.begin(), initial.end());
    MinHeap heap;
    for (int v : initial) {
      if (dist_[v] == kInf) continue;
      if (state_[v] == 0) {
        double shortest = kInf;
        const FanRange fan = m_.fan(v);
        for (int j = fan.begin; j < fan.end; ++j)
          shortest = std::min(shortest, (m_.point(m_.fan_triangle(j).a) - m_.point(v)).sqrnorm());
        state_[v] = dist_[v] * dist_[v] <= kNearRadius * kNearRadius * shortest ? 2 : 1;
      }
      if (state_[v] == 2) ++report.initialised;
      heap.emplace(dist_[v], v);
    }
    return heap;
  }

  /// The update of x from the triangle (x; a, b).
  FrontValue update(const CornerGeometry& g, int a, int b, int x) {
    if (!track_) return FrontValue{triangle_update(g, dist_[a], dist_[b])};
    return front_update(g, dist_[a], dist_[b], kappa_[a], kappa_[b], (gauss(a) + gauss(b) + gauss(x)) / 3);
  }

  /// The update of the vertex at an obtuse corner through the two virtual triangles (x; a, r), (x; r, b).
  FrontValue split_update(int split) {
    const ObtuseSplit s = m_.split(split);
    FrontValue value;
    if (!known(s.vertex)) return value;
    const int f = s.corner / 3, c = s.corner % 3;
    const int x = m_.corner_vertex(s.corner);
    const int a = m_.corner_vertex(3 * f + (c + 1) % 3), b = m_.corner_vertex(3 * f + (c + 2) % 3);
    if (known(a)) {
      const FrontValue first = update(s.first, a, s.vertex, x);
      if (first.d < value.d) value = first;
    }
    if (known(b)) {
      const FrontValue second = update(s.second, s.vertex, b, x);
      if (second.d < value.d) value = second;
    }
    return value;
  }

  void lower(int x, const FrontValue& value, MinHeap& heap) {
    if (value.d < dist_[x]) {
      w_.set(x, value.d);
      kappa_[x] = value.kappa;
      state_[x] = 1;
      heap.emplace(value.d, x);
    }
  }

  /// v accepted at d: its neighbours' tentative values lowered through the triangles around it.
  void accept(int v, double d, MinHeap& heap) {
    const Vec3& pv = m_.point(v);
    const FanRange fan = m_.fan(v);
    for (int j = fan.begin; j < fan.end; ++j) {
      // By value: an update may build another fan and move the storage.
      const FanTriangle t = m_.fan_triangle(j);
      for (int side = 0; side < 2; ++side) {
        const int x = side == 0 ? t.a : t.b;
        if (known(x)) continue;
        const int y = side == 0 ? t.b : t.a;
        const Vec3& px = m_.point(x);
        const Vec3 ev = pv - px;
        FrontValue value;
        if (!(t.obtuse & (1 << side))) {
          if (known(y)) value = update(corner_geometry(ev, m_.point(y) - px), v, y, x);
        } else {  // obtuse angle at x: the two acute virtual triangles of the unfolding
          const int split = m_.obtuse(3 * (t.corner / 3) + (t.corner % 3 + 1 + side) % 3);
          if (split >= 0) value = split_update(split);
        }
        if (value.d == kInf) {
          const double length = ev.norm();
          value = {d + length, track_ ? carried_curvature(kappa_[v], length, gauss(x)) : 0.0};
        }
        lower(x, value, heap);
      }
    }
    // v may be the unfolded vertex r of obtuse corners elsewhere: update those corners too.
    for (int split = m_.first_split_at(v); split >= 0; split = m_.next_split(split)) {
      const int x = m_.corner_vertex(m_.split(split).corner);
      if (known(x)) continue;
      lower(x, split_update(split), heap);
    }
  }

  const FlatMesh& m_;
  const Seeds& seeds_;
  const DistanceOptions& options_;
  MarchWorkspace& w_;
  std::vector<double>& dist_;
  std::vector<double>& kappa_;
  std::vector<std::uint8_t>& state_;
  const bool track_;
  /// The Gaussian curvature at v, computed when the march first needs it: a band touches a small
  /// part of a large mesh.
  double gauss(int v) {
    double& value = gauss_[v];
    if (std::isnan(value)) value = gaussian_curvature(m_, v);
    return value;
  }
  static constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> gauss_;
};

/// Exact initialisation next to the seeds, then fast marching up to options.narrow_band. The result
/// is in w.dist / w.state (accepted = 3) for the vertices of w.touched.
void march(const FlatMesh& m, const Seeds& seeds, const DistanceOptions& options, MarchWorkspace& w,
           DistanceReport& report) {
  w.prepare(m.nv(), seeds.faces.size());
  report.has_interface = !seeds.faces.empty();
  FastMarch march(m, seeds, options, w);
  march.initialise();
  march.run(report);
}

/// The signed result of a whole-mesh march: ±d where accepted within the band, ±∞ elsewhere.
ScalarField signed_result(const Seeds& seeds, const MarchWorkspace& w, double band) {
  ScalarField result(w.dist.size());
  for (std::size_t v = 0; v < result.size(); ++v) {
    const double value = w.state[v] == 3 && w.dist[v] <= band ? w.dist[v] : kInf;
    result[v] = seeds.sign[v] > 0 ? value : seeds.sign[v] < 0 ? -value : 0.0;
  }
  return result;
}

/// DistanceOptions::keep_crossings: the vertices of the seed faces take back their values of φ.
void keep_crossing_values(const FlatMesh& m, const Seeds& seeds, const ScalarField& phi, ScalarField& d) {
  for (int f : seeds.faces)
    for (int c = 0; c < 3; ++c) {
      const int v = m.corner_vertex(3 * f + c);
      d[v] = phi[v];
    }
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void check_level_set(const SurfaceMesh& mesh, const ScalarField& phi) {
  if (phi.size() != mesh.n_vertices())
    throw InputError("signed_distance: the level set has " + std::to_string(phi.size()) + " values for " +
                     std::to_string(mesh.n_vertices()) + " vertices");
  for (double value : phi)
    if (!std::isfinite(value)) throw InputError("signed_distance: the level set has a non-finite value");
}


}  // namespace

struct DistanceSolver::Impl {
  explicit Impl(const SurfaceMesh& m) : mesh(m), flat(m) {}
  const SurfaceMesh& mesh;
  FlatMesh flat;
  double setup_ms = 0;
  MarchWorkspace workspace;
  std::vector<std::uint32_t> face_seen;  ///< redistance: = epoch for the faces searched in this call
  std::uint32_t epoch = 0;

  /// φ: the level set of φ mode (null in region mode), for DistanceOptions::keep_crossings.
  template <class MakeSeeds>
  ScalarField run(const DistanceOptions& options, DistanceReport* report, MakeSeeds make_seeds,
                  const ScalarField* phi = nullptr) {
    DistanceReport local;
    local.setup_ms = std::exchange(setup_ms, 0.0);  // charged to the first call only
    auto start = std::chrono::steady_clock::now();
    // A march over the whole surface reads all of it: built at once, in parallel where it can be.
    if (!std::isfinite(options.narrow_band)) {
      flat.build_all();
      local.setup_ms += milliseconds_since(start);
      start = std::chrono::steady_clock::now();
    }
    const Seeds seeds = make_seeds(flat);
    local.init_ms = milliseconds_since(start);
    start = std::chrono::steady_clock::now();
    march(flat, seeds, options, workspace, local);
    ScalarField d = signed_result(seeds, workspace, options.narrow_band);
    if (phi && options.keep_crossings) keep_crossing_values(flat, seeds, *phi, d);
    local.march_ms = milliseconds_since(start);
    if (report) *report = local;
    return d;
  }
};

DistanceSolver::DistanceSolver(const SurfaceMesh& mesh) {
  const auto start = std::chrono::steady_clock::now();
  impl_ = std::make_unique<Impl>(mesh);
  impl_->setup_ms = milliseconds_since(start);
}
DistanceSolver::~DistanceSolver() = default;
DistanceSolver::DistanceSolver(DistanceSolver&&) noexcept = default;

ScalarField DistanceSolver::signed_distance(const ScalarField& phi, const DistanceOptions& options,
                                            DistanceReport* report) {
  check_level_set(impl_->mesh, phi);
  return impl_->run(options, report, [&](const FlatMesh& m) { return seeds_from_phi(m, phi); }, &phi);
}

ScalarField DistanceSolver::signed_distance_to_region(const DistanceOptions& options, DistanceReport* report) {
  return impl_->run(options, report, [&](const FlatMesh& m) {
    return seeds_from_region(impl_->mesh, m, options.curved_interface);
  });
}

std::vector<int> DistanceSolver::redistance(ScalarField& phi, double width, std::span<const int> near,
                                            DistanceReport* report, const DistanceOptions& keep) {
  Impl& s = *impl_;
  const FlatMesh& m = s.flat;
  if (phi.size() != m.nv()) check_level_set(s.mesh, phi);
  if (!(width > 0)) throw InputError("redistance: the band width must be positive");
  DistanceReport local;
  auto start = std::chrono::steady_clock::now();
  // The zero set, in the faces around `near`: each face once.
  const std::uint32_t epoch = ++s.epoch;
  s.face_seen.resize(m.nf(), 0);
  Seeds seeds;
  seeds.seg_start.push_back(0);
  for (int v : near) {
    if (!std::isfinite(phi[v])) throw InputError(fmt::format("redistance: non-finite level set at vertex {}", v));
    if (phi[v] == 0) seeds.zeros.push_back(v);
    const FanRange fan = m.fan(v);
    for (int j = fan.begin; j < fan.end; ++j) {
      const int f = m.fan_triangle(j).corner / 3;
      if (s.face_seen[f] == epoch) continue;
      s.face_seen[f] = epoch;
      add_phi_seed(m, phi, f, seeds);
    }
  }
  local.init_ms = milliseconds_since(start);
  start = std::chrono::steady_clock::now();
  DistanceOptions options;
  options.narrow_band = width;
  march(m, seeds, options, s.workspace, local);
  std::vector<int> band;
  for (int v : s.workspace.touched)
    if (s.workspace.state[v] == 3 && s.workspace.dist[v] <= width) band.push_back(v);
  std::sort(band.begin(), band.end());
  // keep_crossings: the seed faces' vertices take back φ, which leaves the zero set in place and
  // the far field as marched from it.
  std::vector<std::pair<int, double>> kept;
  if (keep.keep_crossings)
    for (int f : seeds.faces)
      for (int c = 0; c < 3; ++c) kept.emplace_back(m.corner_vertex(3 * f + c), phi[m.corner_vertex(3 * f + c)]);
  for (int v : band) phi[v] = phi[v] > 0 ? s.workspace.dist[v] : phi[v] < 0 ? -s.workspace.dist[v] : 0.0;
  for (const auto& [v, value] : kept) phi[v] = value;
  local.march_ms = milliseconds_since(start);
  if (report) *report = local;
  return band;
}

ScalarField signed_distance(const SurfaceMesh& mesh, const ScalarField& phi, const DistanceOptions& options,
                            DistanceReport* report) {
  check_level_set(mesh, phi);  // before the set-up
  return DistanceSolver(mesh).signed_distance(phi, options, report);
}

ScalarField signed_distance_to_region(const SurfaceMesh& mesh, const DistanceOptions& options,
                                      DistanceReport* report) {
  return DistanceSolver(mesh).signed_distance_to_region(options, report);
}

}  // namespace bodyfit
