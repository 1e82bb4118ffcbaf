#pragma once
// The soak case: two caps of polar angle a = 55° on the unit sphere, their axes 90°
// apart, so they overlap and G(0) is one region. The conormal model with a periodic speed
// (period P, phase 90°) moves the front by S(t) = −(δ/2)(1 − cos 2πt/P) ∈ [−δ, 0]: G shrinks by
// δ and grows back, every period. With δ = 0.7 rad (40°) the neck of G is eroded away, G splits
// into two caps, and they merge again on the way back — 2 splits/merges per period.
//
// Exact solution (the viscosity solution of the level-set equation with a uniform normal speed):
// on the way in G(t) is the erosion of G(0) by |S| (the points of G(0) at distance ≥ |S| from its
// complement; near the neck that is more than the union of the shrunk caps), tabulated once by
// quadrature (a smoothed indicator on a longitude-latitude grid, second order) and interpolated in
// S. At the end of every period it is the opening of G(0) by δ, i.e. G(0) itself. On the way out
// it is the dilation of the eroded set, which has no closed form here (the eroded set keeps a
// bulge towards the old neck: it is not two caps): no exact value is given there (NaN).
//
// Shared by bench/bench_soak.cpp and tests/test_soak.cpp.
#include <bodyfit/geometry.hpp>
#include <bodyfit/mesh.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <unistd.h>
#include <vector>

namespace soak {

constexpr double kPi = std::numbers::pi;

struct SoakCase {
  double h = 0.08;         ///< mesh size (hmax = h, dt = cfl·h)
  double cfl = 0.5;
  double period = 4;       ///< P
  double depth = 0.7;      ///< δ: how far the front goes in (radians on the unit sphere)
  double cap_angle = 55;   ///< degrees
  double separation = 90;  ///< angle between the two axes, degrees
  long iterations = 3000;
  std::string slopes = "fitted";  ///< the cut's Hermite slopes: fitted, faces or linear (no Hermite)

  double speed() const { return depth * kPi / period; }  ///< δ/2 · 2π/P
  /// S(t): the front's displacement (≤ 0) at time t.
  double displacement(double t) const { return -0.5 * depth * (1 - std::cos(2 * kPi * t / period)); }
  std::array<double, 3> axis(int i) const {
    const double half = 0.5 * separation * kPi / 180;
    return {i == 0 ? std::sin(half) : -std::sin(half), 0.0, std::cos(half)};
  }
  /// The case file `bodyfit run` would read.
  std::string toml() const {
    const auto a0 = axis(0), a1 = axis(1);
    return fmt::format(R"(
[surface]
generator = "sphere"
h = {h}
[region]
shape = "cap"
axes = [[{:.17g}, {:.17g}, {:.17g}], [{:.17g}, {:.17g}, {:.17g}]]
angles = [{a}, {a}]
[model]
name = "conormal"
speed = {speed:.17g}
period = {P}
phase = 90
[time]
cfl = {cfl}
iterations = {n}
[remesh]
hmax = {h}
[discretize]
hermite_crossings = {hermite}
fitted_slopes = {fitted}
)",
                       a0[0], a0[1], a0[2], a1[0], a1[1], a1[2], fmt::arg("h", h), fmt::arg("a", cap_angle),
                       fmt::arg("speed", speed()), fmt::arg("P", period), fmt::arg("cfl", cfl),
                       fmt::arg("n", iterations), fmt::arg("hermite", slopes != "linear"),
                       fmt::arg("fitted", slopes == "fitted"));
  }
};

/// |G(t)| of the exact solution, tabulated over S for the way in and the way out.
class ExactArea {
 public:
  explicit ExactArea(const SoakCase& c, int samples = 32) : case_(c), samples_(samples) {
    const double a = c.cap_angle * kPi / 180;
    axes_[0] = c.axis(0), axes_[1] = c.axis(1);
    // The corners of G(0): the two points where the circles cross.
    const double c12 = dot(axes_[0], axes_[1]);
    const double alpha = std::cos(a) / (1 + c12);
    const double gamma = std::sqrt(std::max(0.0, 1 - 2 * alpha * alpha * (1 + c12)));
    std::array<double, 3> sum{}, normal = cross(axes_[0], axes_[1]);
    const double ln = std::sqrt(dot(normal, normal));
    for (int k = 0; k < 3; ++k) sum[k] = axes_[0][k] + axes_[1][k];
    for (int k = 0; k < 3; ++k) {
      corners_[0][k] = alpha * sum[k] + gamma * normal[k] / ln;
      corners_[1][k] = alpha * sum[k] - gamma * normal[k] / ln;
    }
    inward_.resize(std::size_t(samples) + 1);
    for (int i = 0; i <= samples; ++i) {
      const double s = c.depth * i / samples;  // |S|
      inward_[std::size_t(i)] = integrate([&](const std::array<double, 3>& x) { return eroded(x, a, s); });
    }
  }

  /// The exact |G(t)| on the way in and at the ends of the periods; NaN on the way out.
  double at(double t) const {
    const double phase = std::fmod(t, case_.period) / case_.period;
    if (phase > 0.5 + 1e-9 && phase < 1 - 1e-9) return std::numeric_limits<double>::quiet_NaN();
    const std::vector<double>& table = inward_;
    const double u = std::clamp(-case_.displacement(t) / case_.depth, 0.0, 1.0) * samples_;
    const int i = std::min(int(u), samples_ - 1);
    return table[std::size_t(i)] + (u - i) * (table[std::size_t(i) + 1] - table[std::size_t(i)]);
  }
  /// |G(0)| and the deepest state's.
  double initial() const { return inward_.front(); }
  double deepest() const { return inward_.back(); }

 private:
  using P3 = std::array<double, 3>;
  static double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  static P3 cross(const P3& a, const P3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  }
  static double angle(const P3& a, const P3& b) {
    const P3 c = cross(a, b);
    return std::atan2(std::sqrt(dot(c, c)), dot(a, b));
  }
  /// Signed distance-like function of the union of caps of angle r (< 0 inside).
  double caps(const P3& x, double r) const { return std::min(angle(x, axes_[0]), angle(x, axes_[1])) - r; }
  /// The same for the erosion of G(0) = caps(a) by s: s − dist(x, ∂G(0)) inside G(0).
  double eroded(const P3& x, double a, double s) const {
    const double outside = caps(x, a);
    if (outside >= 0) return s + outside;
    double d = 1e30;
    for (int i = 0; i < 2; ++i) {
      // The point of circle i nearest x; on the boundary of G(0) unless it lies inside cap j.
      const P3& u = axes_[std::size_t(i)];
      const P3& other = axes_[std::size_t(1 - i)];
      const double beta = angle(x, u);
      P3 t{x[0] - std::cos(beta) * u[0], x[1] - std::cos(beta) * u[1], x[2] - std::cos(beta) * u[2]};
      const double lt = std::sqrt(dot(t, t));
      if (lt < 1e-12) {  // x on the axis: every point of the circle is at distance a
        d = std::min(d, a);
        continue;
      }
      P3 foot;
      for (int k = 0; k < 3; ++k) foot[std::size_t(k)] = std::cos(a) * u[std::size_t(k)] + std::sin(a) * t[std::size_t(k)] / lt;
      if (angle(foot, other) >= a)  // |a − β|: x may lie in cap j outside cap i (β > a)
        d = std::min(d, std::abs(a - beta));
      else  // the nearest point of the arc of circle i on ∂G(0) is one of its ends, the corners
        d = std::min({d, angle(x, corners_[0]), angle(x, corners_[1])});
    }
    return s - d;
  }
  /// Area of {f < 0} on the unit sphere: a smoothed indicator (second order) on a grid of
  /// 0.35° in polar angle about +z up to the reach of the caps, and in longitude over y ≥ 0 (G is
  /// symmetric about the xz-plane).
  template <class F>
  double integrate(F&& f) const {
    const double step = 0.35 * kPi / 180;
    const double reach = std::min(kPi, 0.5 * case_.separation * kPi / 180 + case_.cap_angle * kPi / 180 + 0.1);
    const int n_theta = int(std::ceil(reach / step)), n_phi = int(std::ceil(kPi / step));
    const double d_theta = reach / n_theta, d_phi = kPi / n_phi;
    double area = 0;
    for (int i = 0; i < n_theta; ++i) {
      const double theta = (i + 0.5) * d_theta, st = std::sin(theta), ct = std::cos(theta);
      double ring = 0;
      for (int j = 0; j < n_phi; ++j) {
        const double phi = (j + 0.5) * d_phi;
        const double value = f(P3{st * std::cos(phi), st * std::sin(phi), ct});
        ring += std::clamp(0.5 - value / step, 0.0, 1.0);
      }
      area += ring * st * d_theta * d_phi;
    }
    return 2 * area;
  }

  SoakCase case_;
  int samples_;
  P3 axes_[2];
  P3 corners_[2];
  std::vector<double> inward_;
};

/// Resident set size of this process, MiB (/proc/self/statm).
inline double rss_mib() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return double(resident) * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

/// Share of the faces below quality 0.3.
inline double share_below(const bodyfit::SurfaceMesh& mesh, double quality) {
  std::size_t below = 0;
  for (auto f : mesh.faces()) below += bodyfit::face_quality(mesh, f) < quality;
  return mesh.n_faces() ? double(below) / double(mesh.n_faces()) : 0.0;
}

}  // namespace soak
