#pragma once
// The stages as the command line runs them, on a mesh in memory: `bodyfit distance`, `advect`,
// `discretize`, `remesh` and `info` read and write files around these functions, and the Python
// module calls the same functions on arrays — the same defaults, checks and results, byte for byte.
#include <bodyfit/advection.hpp>
#include <bodyfit/distance.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/remesh.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace bodyfit {

/// The signed distance to the zero set of `phi`, or (phi null) to the faces whose ref is
/// `region` (the mesh's regions and interface become that split). Infinities (no interface) are
/// written as ±1e300, which Medit files and every reader hold.
ScalarField distance_stage(SurfaceMesh& mesh, const ScalarField* phi, int region, const DistanceOptions& options,
                           DistanceReport* report = nullptr);

/// φ carried by `velocity` over (0, time); a lost characteristic is a NumericalError (a value from
/// the middle of a path would be a wrong answer), and so is a non-finite result.
ScalarField advect_stage(const SurfaceMesh& mesh, const ScalarField& phi, const VectorField& velocity, double time,
                         const AdvectionOptions& options, AdvectionReport* report = nullptr);

struct DiscretizeStageReport {
  DiscretizeReport cut;
  std::optional<RemeshReport> remesh;  ///< when remeshed
  double cut_ms = 0, remesh_ms = 0;
};
/// Cut the zero level set of φ into the mesh, then (with `remesh`) remesh: the face budget is
/// checked first, and hmax defaults to the input's resolution measured before the cut.
DiscretizeStageReport discretize_stage(SurfaceMesh& mesh, const ScalarField& phi, const DiscretizeOptions& cut,
                                       RemeshOptions options, bool remesh);

/// Remesh after checking the face budget of the sizes asked for.
RemeshReport remesh_stage(SurfaceMesh& mesh, const RemeshOptions& options);

/// What a mesh is made of (`bodyfit info`).
struct MeshInfo {
  struct Region {
    std::size_t faces = 0;
    double area = 0;
  };
  std::size_t vertices = 0, edges = 0, faces = 0;
  BoundingBox box;
  QualityStats quality;
  EdgeLengthStats edge_lengths;
  double area = 0;
  std::map<int, Region> regions;
  std::size_t interface_edges = 0;
  double interface_length = 0;
  InterfaceCurves curves;
  int components = 0;
  std::vector<double> loop_lengths;
  long euler = 0;
  std::size_t ridges = 0, corners = 0, required_vertices = 0, required_edges = 0;
};
MeshInfo describe_mesh(const SurfaceMesh& mesh);
/// As JSON (an object; `file` is its first member) or as one screen of aligned text.
std::string to_json(const MeshInfo& info, const std::string& file);
std::string to_text(const MeshInfo& info, const std::string& file);

}  // namespace bodyfit
