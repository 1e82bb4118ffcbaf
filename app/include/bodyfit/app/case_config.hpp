#pragma once
// A run case: the TOML file read by `bodyfit run` (reference: docs/reference/case_file.md).
//
//   [surface]    file = "s.mesh"  |  generator = "sphere" (faces|h, radius) | "terrain" (extent, h,
//                seed, dem, nodata, reproject, max_height, feature_size) | "plane" (size, h)
//   [region]     shape = "refs" (refs = [3]) | "sol" (sol = "phi.sol") | "cap" (axis, angle in
//                degrees, center; or axes = [[..], ..] and angles = [..] for a union of caps) | "disks" (centers = [[x, y], ...], radii = [...])
//                | "balls" (centers = [[x, y, z], ...], radii = [...]: S inside the balls)
//                | "ignitions" (file = a vector layer of points, lines, polygons; radius; time_attribute)
//   [model]      name = "conormal", every other key is the model's own parameter
//   [time]       dt | cfl (Δt = cfl·h);  final_time and/or iterations; max_cfl, narrow_band, keep_crossings, max_substeps,
//                compose_substeps, max_rejections; start = "2026-07-14T13:00:00Z" (the clock time of t = 0)
//   [distance] [advection] [discretize] [remesh]   options of each stage
//   [output]     vtu_every, png_every, field, view, size = [w, h], checkpoint_every, checkpoint_seconds,
//                grid_format
//
// Every table and key is checked (with bodyfit::Parameters): an unknown one is an InputError with a
// suggestion ("case.toml:9: unknown key 'final_tiem' in [time]; did you mean 'final_time'?"), as is
// a wrong type, a value out of range or a missing required key.
//
// Two halves: reading a case (case_config.cpp: apply_override, parse_case, read_case) and setting
// up its run (case_setup.cpp: make_case_surface ... setup_case). They share this header because a
// run needs both and the set-up functions take the CaseConfig.
#include <bodyfit/app/config.hpp>
#include <bodyfit/advection.hpp>
#include <bodyfit/distance.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/mesh.hpp>
#include <bodyfit/remesh.hpp>

#include <toml++/toml.h>

#include <array>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace bodyfit {

struct SurfaceSpec {
  enum class Kind { File, Sphere, Terrain, Plane };
  Kind kind = Kind::Sphere;
  std::filesystem::path file;       ///< Kind::File (relative paths are relative to the case file)
  SphereOptions sphere;             ///< Kind::Sphere
  TerrainOptions terrain;           ///< Kind::Terrain (procedural, or from `dem`)
  std::filesystem::path dem;        ///< Kind::Terrain: a DEM raster instead of the procedural landscape
  NodataMode nodata = NodataMode::hole;      ///< with `dem`: what its NODATA cells become
  Reprojection reproject = Reprojection::none;  ///< with `dem`: a raster in degrees refused, or warped to UTM
  PlaneOptions plane;               ///< Kind::Plane

  /// A terrain or the plane z = 0: a height field z(x, y) (StepContext::is_height_field), on
  /// which the fire model keeps its arrival-time raster and perimeters.
  bool height_field() const { return kind == Kind::Terrain || kind == Kind::Plane; }
};

struct RegionSpec {
  enum class Kind { Refs, Sol, Cap, Disks, Balls, Ignitions };
  Kind kind = Kind::Cap;
  std::vector<int> refs{kInside};   ///< Kind::Refs: face refs of the file that make up G
  std::filesystem::path sol;        ///< Kind::Sol: φ at the vertices of the surface (< 0 inside)
  Vec3 axis{0, 0, 1};               ///< Kind::Cap: unit axis of the cap
  double angle = 45;                ///< Kind::Cap: polar angle, degrees
  /// Kind::Cap with `axes` and `angles` (a union of caps): (unit axis, angle in degrees) each.
  std::vector<std::pair<Vec3, double>> caps;
  Vec3 center{0, 0, 0};             ///< Kind::Cap: centre of the sphere
  std::vector<std::array<double, 3>> disks;  ///< Kind::Disks: (x, y, radius), horizontal distance
  std::vector<std::array<double, 4>> balls;  ///< Kind::Balls: (x, y, z, radius), the part of S in the balls
  /// Kind::Ignitions: a vector layer (GeoJSON, Shapefile, GeoPackage…) of points (disks of
  /// `ignition_radius`), lines (buffers of that half-width) and polygons, in plan view; each
  /// feature ignites at its `time_attribute` (seconds after t = 0, or an ISO 8601 date-time with
  /// [time] start; absent or null: at t = 0). Later ignitions join G when their time comes
  /// (EvolutionOptions::additions).
  std::filesystem::path ignitions;
  double ignition_radius = 0;
  std::string time_attribute;
};

struct TimeSpec {
  double dt = 0;   ///< fixed time step (0: use cfl)
  double cfl = 0;  ///< Δt = cfl·h, h = remesh.hmax when given, else the mean edge length of T^0
  double max_cfl = 0;  ///< sub-steps keep max|V|·Δt_sub ≤ max_cfl·h (0: off; EvolutionOptions::max_cfl)
  bool narrow_band = true;  ///< sub-steps work near the front only (EvolutionOptions::narrow_band)
  bool keep_crossings = true;  ///< EvolutionOptions::keep_crossings
  bool compose_substeps = false;  ///< EvolutionOptions::compose_substeps
  long max_substeps = 10000;  ///< sub-steps one step may take (0: no limit; EvolutionOptions::max_substeps)
  double final_time = std::numeric_limits<double>::infinity();
  long iterations = -1;  ///< −1: no limit (final_time decides)
  /// Steps a run may take (final_time / dt, or iterations; 0: no limit): a Δt far too short for the
  /// run's length is an input error at set-up, naming the count, not a run of 10¹² steps.
  long max_steps = 1000000;
  /// A step the velocity model rejects is retried with half the time step at most this many times
  /// before the run stops (0: stop at the first rejection).
  int max_rejections = 5;
  /// The date-time of t = 0 (ISO 8601 with its zone, as given) and its seconds since the epoch.
  std::string start;
  std::optional<double> start_seconds;
};

struct OutputSpec {
  int vtu_every = 1;              ///< 0: no VTU series
  int png_every = 0;              ///< 0: no PNG snapshots
  std::string field = "region";   ///< region | phi | d | quality | height | a model's point field
  std::string view = "iso";       ///< iso | top | front
  int width = 800, height = 600;
  /// The checkpoint's cadence (0 turns a criterion off); a run always checkpoints at its start,
  /// its end and on SIGINT (docs/reference/running.md).
  int checkpoint_every = 0;         ///< iterations
  double checkpoint_seconds = 30;   ///< wall-clock seconds since the last checkpoint
  /// The format of the model's grid outputs: "tif" (GeoTIFF: CRS, NODATA, units; with GDAL) or
  /// "asc" (ESRI ASCII grid + .prj).
  std::string grid_format = config::have_gdal ? "tif" : "asc";
};

struct CaseConfig {
  std::filesystem::path file;      ///< the case file ("" when parsed from a string)
  std::filesystem::path base_dir;  ///< relative paths in the case are relative to this
  SurfaceSpec surface;
  RegionSpec region;
  std::string model;               ///< plugin name
  toml::table model_parameters;    ///< [model] without `name`
  TimeSpec time;
  DistanceOptions distance;
  AdvectionOptions advection;
  DiscretizeOptions discretize;  ///< as EvolutionOptions::discretize (the same defaults as `bodyfit discretize`)
  RemeshOptions remesh;            ///< `reference` is left empty: the driver sets it
  bool remesh_angle_given = false; ///< [remesh] angle set explicitly (else off on terrains)
  OutputSpec output;
  toml::table effective;           ///< the whole table after overrides (written as outdir/case.toml)
};

/// Apply one "dotted.key=value" override to a table. The value is parsed as a TOML value
/// (0.05, 12, true, "text", [1, 2]); anything that does not parse is taken as a string.
void apply_override(toml::table& table, const std::string& assignment);

/// Read a TOML file (a case, a run's case.toml) and apply the overrides in order, unvalidated.
/// A missing file or a syntax error is an InputError naming the file (and the line).
toml::table read_case_table(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});
/// Validate a case table and turn it into a CaseConfig (throws InputError). File names resolve
/// against the file each value was read from (Parameters::path); a value without one, against
/// `sourceless` — `base_dir` unless given (a case given as text stands for a file in base_dir).
CaseConfig parse_case(const toml::table& table, const std::filesystem::path& base_dir = {});
CaseConfig parse_case(const toml::table& table, const std::filesystem::path& base_dir,
                      const std::filesystem::path& sourceless);
/// Read a case file, apply the overrides in order, validate.
CaseConfig read_case(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

// ---- setting up a run (case_setup.cpp) --------------------------------------------------------

/// The surface S of the case (generated or read), without region labels.
SurfaceMesh make_case_surface(const CaseConfig& config);
/// What S is built from, for the model (VelocityModel::set_surface): the DEM, its coordinate system
/// and, when the case reprojects it, the one it had (reads the DEM; empty without one).
SurfaceSource case_surface_source(const CaseConfig& config);
/// The initial level set of the case on the vertices of `surface` (negative inside G(0)), or an
/// empty field when the region comes from face refs (RegionSpec::Kind::Refs).
ScalarField initial_level_set(const CaseConfig& config, const SurfaceMesh& surface);
/// The fixed reference surface S for the remesher: the exact sphere for a generated sphere, else
/// the triangles of `surface` (call before any remeshing).
std::shared_ptr<const ReferenceSurface> make_case_reference(const CaseConfig& config, const SurfaceMesh& surface);
/// Everything a run needs before its first iteration.
struct CaseSetup {
  SurfaceMesh mesh;          ///< T^0: S with G(0) meshed (garbage-collected)
  EvolutionOptions options;  ///< dt, end, stage options, remesh reference (no callbacks)
  double h = 0;              ///< the mesh size of Δt = cfl·h
};
/// Build S, its reference, T^0 (cut + remesh, or refs + remesh) and the evolution options.
CaseSetup setup_case(const CaseConfig& config);

/// Label `surface`'s faces from its refs (RegionSpec::Kind::Refs): refs listed are G.
void label_from_refs(const CaseConfig& config, SurfaceMesh& surface);

}  // namespace bodyfit
