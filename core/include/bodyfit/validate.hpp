#pragma once
// Mesh validity checker: lists what is wrong with a SurfaceMesh (structure, geometry, regions,
// interface, expected topology) as human-readable lines. Every mesher/remesher test runs it.
#include <bodyfit/mesh.hpp>

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace bodyfit {

struct ValidateOptions {
  /// At most this many problem descriptions are kept (all are counted).
  std::size_t max_problems = 20;
  /// A face is degenerate when area ≤ degenerate_area_ratio × (its longest edge)².
  double degenerate_area_ratio = 1e-12;
  /// Two faces sharing an edge are folded onto each other (inverted or inconsistently oriented
  /// geometry) when the angle between their normals exceeds this (degrees); ≤ 0 disables.
  double fold_angle_degrees = 160;
  /// Check region labels (kInside/kOutside) against e:interface, and the interface curves.
  bool check_regions = true;
  /// Require φ = 0 (|φ| ≤ phi_tolerance) at every vertex of an interface edge.
  bool check_phi_on_interface = false;
  double phi_tolerance = 0;
  /// Expected topology, checked when given.
  std::optional<long> euler_characteristic{};
  std::optional<std::size_t> boundary_loops{};
  /// Distance from a point to a reference surface, and the largest distance allowed for vertices.
  std::function<double(const Vec3&)> distance_to_reference{};
  double max_reference_distance = 0;
};

struct ValidationReport {
  std::vector<std::string> problems;  ///< the first max_problems descriptions
  std::size_t problem_count = 0;      ///< every problem found
  bool ok() const { return problem_count == 0; }
  /// All descriptions on separate lines, with a note when some were left out.
  std::string summary() const;
};

/// Checks, each reported with the element index:
///  - deleted elements remaining (mesh not garbage-collected), isolated vertices, non-finite points;
///  - broken halfedge structure (face not a triangle, opposite/next inconsistent), non-manifold
///    vertices (several fans), duplicated faces (same three points);
///  - degenerate (zero-area) faces, folded neighbours (see fold_angle_degrees);
///  - with check_regions: labels other than kInside/kOutside; an edge is interface iff its two
///    faces have different labels (never on the boundary), and interface edges carry ref 10;
///    every interior vertex has 0 or 2 interface edges (closed curves, or curves ending on the
///    boundary);
///  - the optional expected Euler characteristic, boundary loop count and reference distance.
ValidationReport validate_mesh(const SurfaceMesh& mesh, const ValidateOptions& options = {});

}  // namespace bodyfit
