#pragma once
// The checks every entry point shares: the budget of faces a command may build, the
// budget of sub-steps an advection may take, and finiteness of fields. One place, so a command,
// a case and a stage refuse the same things with the same words.
//
//   check_face_budget(estimate, "mesh sphere --faces 4000000000");  // InputError above the limit
//   require_finite(phi, "advect: the advected level set");          // NumericalError on NaN/Inf
#include <bodyfit/mesh.hpp>

#include <cstddef>
#include <span>
#include <string_view>

namespace bodyfit {

struct RemeshOptions;

/// Peak memory of the heaviest command per face of its mesh: `bodyfit run` on a sphere, measured
/// with /usr/bin/time -v (docs/reference/running.md, "Limits"). Used to turn a face budget into bytes.
inline constexpr double kBytesPerFace = 710;

/// The largest mesh (in faces) a command may build or remesh to. The default is the number of
/// faces whose `run` fits in three quarters of the machine's physical memory (kBytesPerFace each);
/// set_max_faces(0) removes the limit (the driver's --max-faces).
std::size_t max_faces();
void set_max_faces(std::size_t faces);
/// The default of max_faces() on this machine.
std::size_t default_max_faces();

/// Throws InputError when `estimated_faces` (NaN or infinite included) exceeds max_faces(), with
/// the estimate, its memory and how to raise the limit: "<what>: about 4.0e+09 faces (about
/// 2.8 TB), above the limit of 2.5e+07 faces; ...". Called before any heavy work.
void check_face_budget(double estimated_faces, std::string_view what);

/// Faces of near-equilateral triangles of edge h covering `area` (area / (√3/4 h²)).
double faces_for_edge_length(double area, double h);

/// A lower bound of the faces remesh() will produce: no edge longer than hmax (its default when
/// 0: the input's resolution, resolution_length) over the surface's area. Non-finite for hmax < 0 or NaN.
double estimate_remesh_faces(const SurfaceMesh& mesh, const RemeshOptions& options);

/// The index of the first NaN or infinite value (of a component, for vectors); npos when none.
std::size_t find_non_finite(std::span<const double> values);
std::size_t find_non_finite(std::span<const Vec3> values);

/// Throws NumericalError naming the first non-finite value ("<what>: NaN at vertex 12 (of 400)");
/// `what` is the stage and the field. Vertex numbers are counted from 1, as in the files.
void require_finite(std::span<const double> values, std::string_view what);
void require_finite(std::span<const Vec3> values, std::string_view what);

}  // namespace bodyfit
