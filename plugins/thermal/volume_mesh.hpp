#pragma once
// VolumeMesh: the tetrahedral mesh of the solid Ω whose skin is the fixed surface S, made by TetGen
// (library API, never files) with S kept exactly: every triangle of S is a boundary face, and
// surface vertex i is volume vertex i, so P1 fields on S and on ∂Ω are the same vectors.
#include <bodyfit/mesh.hpp>

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace bodyfit::thermal {

struct VolumeMesh {
  /// Vertices. The first n_surface_vertices are the vertices of S, in S's order, bit-identical;
  /// the others are TetGen's interior Steiner points.
  std::vector<Vec3> points;
  /// Tetrahedra, positively oriented: det(b − a, c − a, d − a) > 0.
  std::vector<std::array<int, 4>> tets;
  /// Boundary faces, oriented outward (right-hand rule), vertex indices < n_surface_vertices.
  std::vector<std::array<int, 3>> boundary_faces;
  /// For each boundary face, the index of the face of S it is (a bijection onto S's faces).
  std::vector<int> boundary_source_face;
  int n_surface_vertices = 0;

  std::size_t n_vertices() const { return points.size(); }
  std::size_t n_tets() const { return tets.size(); }
};

struct TetrahedralizeOptions {
  /// TetGen -q: bound on the radius-edge ratio of the tetrahedra (≥ 1; TetGen may not terminate
  /// much below 1.1). Measured on spheres (docs/validation/thermal_solvers.md): 1.1-2 give the same smallest
  /// dihedral angles (7-9°, slivers are TetGen's optimisation's business) once a volume bound is
  /// set; without one, 1.2 keeps them about 1° larger than 1.4 and 3° larger than 2.
  double radius_edge_ratio = 1.2;
  /// TetGen -a: bound on the volume of every tetrahedron, 0 = none (then the interior is only as
  /// fine as the quality bound needs: mean edge 1.5-2 h). With S of mean edge h, regular_tet_volume(h)
  /// = h³/(6√2) gives a mean tetrahedron edge of 0.90 h, 1.4× that (≈ h³/6) about h.
  double max_volume = 0;
  /// Look for self-intersections of S before calling TetGen (a grid over the triangles, O(n) for
  /// a well-spread mesh: 45 ms for 20k faces). TetGen's own detection ends in a crash in Debian's
  /// build (see isolate), so only switch this off for surfaces known to be clean.
  bool check_self_intersections = true;
  /// Run TetGen in a child process (fork) and read its mesh through a pipe. Debian's TetGen 1.5.0
  /// does not survive its own errors: terminatetetgen() frees the mesh and throws, then the
  /// unwinding frees it again (a double free: SIGSEGV or SIGABRT), and its 302 assertions are
  /// compiled in (abort). Isolated, such a failure becomes an InputError quoting TetGen's last
  /// messages instead of killing the caller. Costs a fork and a copy of the mesh (a few ms).
  bool isolate = true;
};

/// Volume of the regular tetrahedron of edge h: the natural TetrahedralizeOptions::max_volume.
inline double regular_tet_volume(double h) { return h * h * h / (6.0 * std::sqrt(2.0)); }

/// Tetrahedralise the solid bounded by `surface` (TetGen switches p Y z Q q<ratio> [a<volume>]).
/// The surface is checked first (check_solid_surface); every failure, ours or TetGen's (when
/// isolated), is an InputError naming it.
VolumeMesh tetrahedralize(const SurfaceMesh& surface, const TetrahedralizeOptions& options = {});

struct VolumeStats {
  std::size_t vertices = 0, tets = 0, boundary_faces = 0;
  double volume = 0;
  double min_dihedral_deg = 0, max_dihedral_deg = 0;  ///< over all tetrahedra, degrees
  double mean_edge = 0;                               ///< mean length of the tetrahedra's edges (with repeats)
};
VolumeStats volume_stats(const VolumeMesh& mesh);

/// Signed volume of a tetrahedron: det(b − a, c − a, d − a)/6.
double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

}  // namespace bodyfit::thermal
