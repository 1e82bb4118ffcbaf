#pragma once
// Reading and writing meshes and fields.
//
//   .mesh / .meshb   Medit ASCII / binary (MMG, Mshdist, Advection, FreeFEM): vertices, triangles,
//                    edges, ridges, corners, required vertices and edges, with their refs
//   .sol  / .solb    Medit solution files: scalar or vector fields at the vertices
//   .obj .off .ply .stl  OBJ, OFF, PLY read by bodyfit's parsers, STL by OpenMesh; all written by OpenMesh
//   .vtu / .pvd      VTK XML unstructured grid (binary appended) and ParaView time series
//
// Every reader validates what it reads: a malformed or truncated file, an index out of range,
// NaN/Inf coordinates, a non-manifold edge or vertex, a zero-area face, or a field whose size does
// not match the mesh throws InputError naming the file, the line (or byte offset) and what was
// expected. Every writer writes to a temporary file in the target's directory and renames it, so a
// failed or interrupted write never leaves a half-written file behind.
#include <bodyfit/mesh.hpp>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace bodyfit {

struct ReadOptions {
  /// Reject faces whose area is below this fraction of (mean edge length)².
  double min_relative_area = 1e-14;
};

/// Read any supported mesh format (.mesh .meshb .obj .off .ply .stl .vtu), chosen by extension.
/// Medit refs and tags map onto the mesh properties (see docs/reference/formats.md); e:interface is set on
/// edges listed with ref 10 and on edges between a face of region 3 and a face of another region.
SurfaceMesh read_mesh(const std::filesystem::path& file, const ReadOptions& options = {});
/// A mesh from arrays (the Python module's bodyfit.Mesh): `xyz` holds 3 coordinates per vertex,
/// `triangles` 3 vertex indices (0-based) per face, `regions` one ref per face (empty: all 0).
/// Checked as every reader checks a file; errors name `origin` and the vertex or triangle (1-based).
SurfaceMesh mesh_from_arrays(std::span<const double> xyz, std::span<const std::int64_t> triangles,
                             std::span<const int> regions, const std::string& origin,
                             const ReadOptions& options = {});
/// Write any supported mesh format (.mesh .meshb .obj .off .ply .stl .vtu), chosen by extension.
/// .mesh/.meshb keep refs and tags: Edges lists interface (ref 10), ridge, required, non-zero-ref
/// and boundary edges. Deleted elements are skipped and the vertices renumbered in order.
void write_mesh(const SurfaceMesh& mesh, const std::filesystem::path& file);

/// A field at the vertices: `dimension` components per vertex, stored vertex-major.
struct SolField {
  std::string name;
  int dimension = 1;  ///< 1 (scalar) or the space dimension (vector)
  std::vector<double> values;
  std::size_t size() const { return dimension ? values.size() / std::size_t(dimension) : 0; }
};

/// Read the first field of a .sol/.solb file; `expected_vertices` (if non-zero) must match.
SolField read_sol(const std::filesystem::path& file, std::size_t expected_vertices = 0);
/// Read all fields of a .sol/.solb file.
std::vector<SolField> read_sol_all(const std::filesystem::path& file, std::size_t expected_vertices = 0);
void write_sol(const std::filesystem::path& file, const std::vector<SolField>& fields);

/// Convenience: scalar and vector fields at vertices.
ScalarField read_scalar_sol(const std::filesystem::path& file, std::size_t expected_vertices);
VectorField read_vector_sol(const std::filesystem::path& file, std::size_t expected_vertices);
void write_scalar_sol(const std::filesystem::path& file, const ScalarField& values);
void write_vector_sol(const std::filesystem::path& file, const VectorField& values);

/// Fields attached to a VTU file (point data at vertices or cell data at faces).
struct VtuFields {
  std::vector<std::pair<std::string, ScalarField>> point_scalars;
  std::vector<std::pair<std::string, VectorField>> point_vectors;
  std::vector<std::pair<std::string, std::vector<double>>> cell_scalars;
};
/// Write the mesh as a VTK XML UnstructuredGrid (raw binary appended data). The face region and
/// quality and the vertex φ are always written; `fields` adds more.
void write_vtu(const SurfaceMesh& mesh, const std::filesystem::path& file, const VtuFields& fields = {});
/// Read a VTK XML UnstructuredGrid of triangles (bodyfit's own, or one ParaView saved without
/// compression: raw or base64 appended data, inline base64 or ASCII, UInt32 or UInt64 headers): the
/// cell data "region" gives the regions and the point data "phi" φ; the other fields go to
/// `fields` when given. read_mesh reads .vtu files through it.
SurfaceMesh read_vtu(const std::filesystem::path& file, VtuFields* fields = nullptr, const ReadOptions& options = {});

/// A ParaView time series: each add() appends a (time, file) entry and rewrites the .pvd
/// atomically, so the collection stays valid if the run is killed between two steps.
class PvdWriter {
 public:
  explicit PvdWriter(std::filesystem::path pvd_file);
  /// Re-read an existing .pvd (for --resume), keeping entries with time ≤ max_time.
  static PvdWriter resume(std::filesystem::path pvd_file, double max_time);
  /// `dataset` is relative to the .pvd's directory.
  void add(double time, const std::filesystem::path& dataset);
  std::size_t size() const { return entries_.size(); }

 private:
  void flush() const;
  std::filesystem::path file_;
  std::vector<std::pair<double, std::string>> entries_;
};

}  // namespace bodyfit
