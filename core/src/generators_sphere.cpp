// Geodesic spheres with any face count N ≥ 20 within ±10 %.
//
// Three constructions, chosen by the face count they give:
//  - class I (subdivided icosahedron, frequency k, 20k² faces): each icosahedron face is split into
//    k² triangles along great-circle arcs (slerp between edge points), which keeps them
//    near-equilateral. Used whenever 20k² is the closest geodesic count (2420, 9680, ... are exact).
//  - Goldberg–Coxeter class II/III (a, b), 20(a² + ab + b²) faces: the triangular lattice is laid on
//    each icosahedron face rotated so that the face's corners are lattice points (a, b) apart; the
//    lattice points are mapped radially to the sphere and triangulated by their convex hull (which,
//    for points on a sphere, is the spherical Delaunay triangulation).
//  - below ~300 faces some N have no geodesic count within 10 % (e.g. 40, 290): then N/2 + 2 points
//    are spread by Coulomb repulsion (the Thomson problem) and triangulated by their convex hull.
// The hull-based meshes finish with a few sweeps of tangential smoothing (re-triangulated each time),
// which lifts the minimum quality of the projected lattice near the icosahedron's corners.
#include <bodyfit/generators.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/guards.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>

namespace bodyfit {
namespace {

using Points = std::vector<Vec3>;
using Triangles = std::vector<std::array<int, 3>>;

const double kGolden = (1.0 + std::sqrt(5.0)) / 2.0;

Points icosahedron_vertices() {
  const double t = kGolden;
  Points ico = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : ico) p.normalize();
  return ico;
}
// Outward-oriented faces of the icosahedron above.
const int kIcoFaces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                              {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                              {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                              {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};

Vec3 slerp(const Vec3& a, const Vec3& b, double t) {
  double omega = std::acos(std::clamp(OpenMesh::dot(a, b), -1.0, 1.0));
  if (omega < 1e-15) return a;
  double s = std::sin(omega);
  return (std::sin((1 - t) * omega) / s) * a + (std::sin(t * omega) / s) * b;
}

// Point (i, j) of the k-lattice on the spherical triangle (a, b, c): i steps toward b, j toward c.
Vec3 lattice_point(const Vec3& a, const Vec3& b, const Vec3& c, int k, int i, int j) {
  if (i + j == 0) return a;
  int row = i + j;
  Vec3 p = slerp(a, b, double(row) / k);
  Vec3 q = slerp(a, c, double(row) / k);
  Vec3 x = slerp(p, q, double(j) / row);
  return x.normalized();
}

// Class I geodesic sphere of frequency k on the unit sphere (20k² faces).
SurfaceMesh class_one_sphere(int k) {
  const Points ico = icosahedron_vertices();
  SurfaceMesh mesh;
  // Shared points (icosahedron vertices and edge points) are keyed by the icosahedron edge they
  // lie on, so neighbouring faces reuse the same vertex.
  std::map<std::tuple<int, int, int>, VertexHandle> shared;
  auto key_of = [&](const int f[3], int i, int j) -> std::tuple<int, int, int> {
    int l = k - i - j;  // weights (l, i, j) on (a, b, c)
    int w[3] = {l, i, j};
    int nz = (w[0] > 0) + (w[1] > 0) + (w[2] > 0);
    if (nz == 3) return {-1, -1, -1};
    if (nz == 1) {
      int m = w[0] ? 0 : w[1] ? 1 : 2;
      return {f[m], -1, 0};
    }
    int m0 = -1, m1 = -1;
    for (int m = 0; m < 3; ++m)
      if (w[m] > 0) (m0 < 0 ? m0 : m1) = m;
    int v0 = f[m0], v1 = f[m1], s = w[m1];
    if (v0 > v1) {
      std::swap(v0, v1);
      s = k - s;
    }
    return {v0, v1, s};
  };

  for (const auto& f : kIcoFaces) {
    const Vec3 &a = ico[f[0]], &b = ico[f[1]], &c = ico[f[2]];
    std::vector<std::vector<VertexHandle>> grid(k + 1);
    for (int i = 0; i <= k; ++i) {
      grid[i].resize(k + 1 - i);
      for (int j = 0; i + j <= k; ++j) {
        auto key = key_of(f, i, j);
        if (std::get<0>(key) >= 0) {
          auto it = shared.find(key);
          if (it != shared.end()) {
            grid[i][j] = it->second;
            continue;
          }
        }
        auto v = mesh.add_vertex(lattice_point(a, b, c, k, i, j));
        if (std::get<0>(key) >= 0) shared[key] = v;
        grid[i][j] = v;
      }
    }
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        mesh.add_face(grid[i][j], grid[i + 1][j], grid[i][j + 1]);
        if (i + j + 1 < k) mesh.add_face(grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]);
      }
  }
  return mesh;
}

// ---- convex hull of points on the unit sphere (incremental, Bowyer–Watson on the sphere) ------

double det3(const Vec3& a, const Vec3& b, const Vec3& c) { return OpenMesh::dot(OpenMesh::cross(a, b), c); }

class SphereHull {
 public:
  explicit SphereHull(const Points& points) : p_(points) {}

  // Triangulates all points; they must be distinct, on the unit sphere, and not all coplanar.
  Triangles run() {
    const int n = int(p_.size());
    int i0 = 0, i1 = 0, i2 = 0, i3 = 0;
    for (int i = 0; i < n; ++i)
      if ((p_[i] - p_[i0]).sqrnorm() > (p_[i1] - p_[i0]).sqrnorm()) i1 = i;
    double best = -1;
    for (int i = 0; i < n; ++i) {
      double d = OpenMesh::cross(p_[i] - p_[i0], p_[i1] - p_[i0]).sqrnorm();
      if (d > best) best = d, i2 = i;
    }
    best = -1;
    for (int i = 0; i < n; ++i) {
      double d = std::abs(det3(p_[i1] - p_[i0], p_[i2] - p_[i0], p_[i] - p_[i0]));
      if (d > best) best = d, i3 = i;
    }
    if (det3(p_[i1] - p_[i0], p_[i2] - p_[i0], p_[i3] - p_[i0]) > 0) std::swap(i1, i2);
    // Now i3 lies below the plane (i0, i1, i2) oriented by the right-hand rule: all outward.
    add_face(i0, i1, i2), add_face(i0, i3, i1), add_face(i1, i3, i2), add_face(i2, i3, i0);
    link_all();
    std::vector<char> done(n, 0);
    done[i0] = done[i1] = done[i2] = done[i3] = 1;
    for (int i = 0; i < n; ++i)
      if (!done[i]) insert(i);
    Triangles out;
    for (const auto& f : faces_)
      if (f.alive) out.push_back(f.v);
    return out;
  }

 private:
  struct Face {
    std::array<int, 3> v;
    std::array<int, 3> n{-1, -1, -1};  // n[i]: neighbour across edge (v[i], v[i+1])
    bool alive = true;
  };

  int add_face(int a, int b, int c) {
    faces_.push_back({{a, b, c}});
    ++alive_;
    return int(faces_.size()) - 1;
  }
  void kill(int f) {
    faces_[f].alive = false;
    --alive_;
  }
  /// Drop the dead faces, keeping the live ones in their order (so the triangles come out in the
  /// same order): each insertion kills a few faces and appends a few more, and without this the
  /// array grew to ~25 faces per point (350 MB for a million-face sphere, the run's peak).
  void compact() {
    std::vector<int> index(faces_.size(), -1);
    int kept = 0;
    for (std::size_t f = 0; f < faces_.size(); ++f)
      if (faces_[f].alive) index[f] = kept++;
    for (std::size_t f = 0; f < faces_.size(); ++f)
      if (faces_[f].alive) {
        Face face = faces_[f];
        for (int& g : face.n) g = index[std::size_t(g)];
        faces_[std::size_t(index[f])] = face;
      }
    faces_.resize(std::size_t(kept));
    last_ = index[std::size_t(last_)];
  }
  void link_all() {
    std::map<std::pair<int, int>, std::pair<int, int>> edges;
    for (int f = 0; f < int(faces_.size()); ++f)
      for (int i = 0; i < 3; ++i) edges[{faces_[f].v[i], faces_[f].v[(i + 1) % 3]}] = {f, i};
    for (int f = 0; f < int(faces_.size()); ++f)
      for (int i = 0; i < 3; ++i) faces_[f].n[i] = edges.at({faces_[f].v[(i + 1) % 3], faces_[f].v[i]}).first;
  }
  // Signed distance of q above the plane of face f (relative to the unit sphere).
  double height(int f, const Vec3& q) const {
    const auto& v = faces_[f].v;
    Vec3 nrm = OpenMesh::cross(p_[v[1]] - p_[v[0]], p_[v[2]] - p_[v[0]]);
    double len = nrm.norm();
    return len > 0 ? OpenMesh::dot(q - p_[v[0]], nrm) / len : 0;
  }
  bool visible(int f, const Vec3& q) const { return height(f, q) > 1e-13; }

  int locate(const Vec3& q) {
    int f = last_;
    for (int step = 0; step < 4 * int(faces_.size()) && f >= 0; ++step) {
      if (visible(f, q)) return f;
      const auto& face = faces_[f];
      int next = -1;
      double worst = 0;
      for (int i = 0; i < 3; ++i) {
        double d = det3(p_[face.v[i]], p_[face.v[(i + 1) % 3]], q);
        if (d < worst) worst = d, next = face.n[i];
      }
      f = next;
    }
    // The walk assumes the origin inside the hull; fall back to a scan if it did not end.
    int best = -1;
    double best_h = 0;
    for (int g = 0; g < int(faces_.size()); ++g)
      if (faces_[g].alive) {
        double h = height(g, q);
        if (h > best_h) best_h = h, best = g;
      }
    return best_h > 1e-13 ? best : -1;
  }

  void insert(int pi) {
    const Vec3& q = p_[pi];
    int start = locate(q);
    if (start < 0) throw std::logic_error("sphere: point inside the hull (duplicate point)");
    std::vector<int> visible_faces{start}, stack{start};
    kill(start);
    while (!stack.empty()) {
      int f = stack.back();
      stack.pop_back();
      for (int g : faces_[f].n)
        if (faces_[g].alive && visible(g, q)) {
          kill(g);
          visible_faces.push_back(g);
          stack.push_back(g);
        }
    }
    std::vector<int> created;  // the cone of new faces, one per horizon edge
    for (int f : visible_faces)
      for (int i = 0; i < 3; ++i) {
        int g = faces_[f].n[i];
        if (!faces_[g].alive) continue;
        int a = faces_[f].v[i], b = faces_[f].v[(i + 1) % 3];
        int nf = add_face(a, b, pi);
        faces_[nf].n[0] = g;
        for (int j = 0; j < 3; ++j)
          if (faces_[g].v[j] == b && faces_[g].v[(j + 1) % 3] == a) faces_[g].n[j] = nf;
        created.push_back(nf);
      }
    for (int nf : created) {
      // The new face starting where this one's horizon edge ends (the horizon is short).
      int other = -1;
      for (int g : created)
        if (faces_[g].v[0] == faces_[nf].v[1]) other = g;
      faces_[nf].n[1] = other;
      faces_[other].n[2] = nf;
    }
    last_ = created.front();
    if (faces_.size() > 2 * std::size_t(alive_) + 4096) compact();
  }

  const Points& p_;
  std::vector<Face> faces_;
  int alive_ = 0;
  int last_ = 0;
};

// ---- point sets ---------------------------------------------------------------------------------

// Goldberg–Coxeter (a, b) lattice points of every icosahedron face, each point once.
Points goldberg_coxeter_points(int a, int b) {
  const Points ico = icosahedron_vertices();
  const long t = long(a) * a + long(a) * b + long(b) * b;
  Points out = ico;
  for (const auto& f : kIcoFaces) {
    // Lattice point (i, j) = i e1 + j e2; corners 0, (a, b) and its 60° rotation (−b, a + b).
    // Barycentric numerators over t: v from the corner (a, b), w from (−b, a + b).
    for (long i = -b; i <= a; ++i)
      for (long j = 0; j <= a + b; ++j) {
        long vn = i * (a + b) + long(b) * j, wn = long(a) * j - long(b) * i, un = t - vn - wn;
        if (un < 0 || vn < 0 || wn < 0) continue;
        int zeros = (un == 0) + (vn == 0) + (wn == 0);
        if (zeros >= 2) continue;  // an icosahedron vertex, already in
        if (zeros == 1) {          // on an edge: the face holding the edge as (low → high) owns it
          int from = un == 0 ? f[1] : vn == 0 ? f[2] : f[0];
          int to = un == 0 ? f[2] : vn == 0 ? f[0] : f[1];
          if (from > to) continue;
        }
        out.push_back((double(un) * ico[f[0]] + double(vn) * ico[f[1]] + double(wn) * ico[f[2]]).normalized());
      }
  }
  return out;
}

// n points spread over the sphere: a Fibonacci spiral relaxed by Coulomb repulsion.
Points repelled_points(int n) {
  Points p(n);
  const double golden_angle = 2 * M_PI * (1 - 1 / kGolden);
  for (int i = 0; i < n; ++i) {
    double z = 1 - (2.0 * i + 1) / n, r = std::sqrt(std::max(0.0, 1 - z * z));
    p[i] = Vec3(r * std::cos(i * golden_angle), r * std::sin(i * golden_angle), z);
  }
  const double spacing = std::sqrt(4 * M_PI / n);
  Points force(n);
  for (int it = 0; it < 150; ++it) {
    double max_f = 0;
    for (int i = 0; i < n; ++i) {
      Vec3 f(0, 0, 0);
      for (int j = 0; j < n; ++j)
        if (j != i) {
          Vec3 d = p[i] - p[j];
          double r2 = d.sqrnorm();
          f += d / (r2 * std::sqrt(r2));
        }
      force[i] = project_tangent(f, p[i]);
      max_f = std::max(max_f, force[i].norm());
    }
    if (max_f <= 0) break;
    double step = 0.05 * spacing * (1 - 0.9 * it / 150.0) / max_f;
    for (int i = 0; i < n; ++i) p[i] = (p[i] + step * force[i]).normalized();
  }
  return p;
}

double min_quality(const Points& p, const Triangles& tris) {
  double q = 1;
  for (const auto& t : tris) q = std::min(q, triangle_quality(p[t[0]], p[t[1]], p[t[2]]));
  return q;
}

// Tangential Laplacian smoothing on the unit sphere, re-triangulating after each sweep; keeps the
// best (highest minimum quality) state seen.
Triangles smooth_on_sphere(Points& p, Triangles tris, int sweeps) {
  double best_q = min_quality(p, tris);
  Points best_p = p;
  Triangles best_t = tris;
  for (int s = 0; s < sweeps; ++s) {
    Points sum(p.size(), Vec3(0, 0, 0));
    std::vector<int> count(p.size(), 0);
    for (const auto& t : tris)
      for (int i = 0; i < 3; ++i) {
        sum[t[i]] += p[t[(i + 1) % 3]] + p[t[(i + 2) % 3]];
        count[t[i]] += 2;
      }
    for (std::size_t i = 0; i < p.size(); ++i)
      if (count[i]) p[i] = (0.5 * p[i] + 0.5 * sum[i] / count[i]).normalized();
    tris = SphereHull(p).run();
    double q = min_quality(p, tris);
    if (q > best_q) best_q = q, best_p = p, best_t = tris;
  }
  p = best_p;
  return best_t;
}

SurfaceMesh mesh_from(const Points& p, const Triangles& tris) {
  SurfaceMesh mesh;
  std::vector<VertexHandle> v;
  v.reserve(p.size());
  for (const auto& x : p) v.push_back(mesh.add_vertex(x));
  for (const auto& t : tris) mesh.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return mesh;
}

struct SpherePlan {
  int a = 1, b = 0;        // geodesic (a, b); a = 0 means a repelled point set
  std::size_t points = 0;  // for the repelled point set
};

SpherePlan plan_sphere(std::size_t faces) {
  SpherePlan best;
  double best_err = 1e300;
  const int a_max = int(std::sqrt(double(faces) / 20.0 * 1.2)) + 2;
  for (int a = 1; a <= a_max; ++a)
    for (int b = 0; b <= a; ++b) {
      double count = 20.0 * (double(a) * a + double(a) * b + double(b) * b);
      double err = std::abs(count - double(faces));
      // Ties go to class I (b = 0), then to the first found.
      if (err < best_err - 1e-9 || (std::abs(err - best_err) <= 1e-9 && b == 0 && best.b != 0)) {
        best_err = err;
        best = {a, b, 0};
      }
    }
  if (best_err <= 0.1 * double(faces)) return best;
  std::size_t even = faces + (faces % 2);  // a closed triangulated sphere has F = 2V − 4
  return {0, 0, even / 2 + 2};
}

}  // namespace

SurfaceMesh make_sphere(const SphereOptions& options) {
  if (options.faces < 20) throw InputError("sphere: --faces must be at least 20");
  if (!(options.radius > 0) || !std::isfinite(options.radius)) throw InputError("sphere: --radius must be positive");
  check_face_budget(double(options.faces), fmt::format("sphere of {} faces", options.faces));
  const SpherePlan plan = plan_sphere(options.faces);
  SurfaceMesh mesh;
  if (plan.a > 0 && plan.b == 0) {
    mesh = class_one_sphere(plan.a);
  } else {
    Points p = plan.a > 0 ? goldberg_coxeter_points(plan.a, plan.b) : repelled_points(int(plan.points));
    Triangles tris = SphereHull(p).run();
    tris = smooth_on_sphere(p, std::move(tris), plan.a > 0 ? 0 : 3);
    mesh = mesh_from(p, tris);
  }
  for (auto v : mesh.vertices()) {
    Vec3 unit = mesh.point(v).normalized();
    mesh.set_point(v, options.center + options.radius * unit);
  }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
}

}  // namespace bodyfit
