// Setting up a run from a validated case: the surface S, its reference for the remesher, the
// initial region G(0) meshed into T^0, and the evolution options.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/app/coordinate_system.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/projection.hpp>
#include <bodyfit/app/vector_io.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>

namespace bodyfit {
namespace {

/// The steps the case asks for (final_time / Δt, or iterations), refused above [time] max_steps.
void check_step_count(const TimeSpec& time, double dt, std::size_t faces) {
  double steps = std::isfinite(time.final_time) ? std::ceil(time.final_time / dt - 1e-9) : HUGE_VAL;
  if (time.iterations >= 0) steps = std::min(steps, double(time.iterations));
  if (time.max_steps <= 0 || !(steps > double(time.max_steps))) return;
  const std::string length = time.iterations >= 0 ? fmt::format("iterations = {}", time.iterations)
                                                  : fmt::format("final_time = {:.6g} / dt = {:.6g}", time.final_time, dt);
  throw InputError(fmt::format("[time] {} is {:.3g} steps ({:.3g} face-steps at the {} faces of T^0), above [time] "
                               "max_steps = {}: give a longer dt (or cfl), a shorter final_time or fewer iterations, "
                               "or raise max_steps (0: no limit)",
                               length, steps, steps * double(faces), faces, time.max_steps));
}

/// One feature of an ignition layer: where, in plan view, and when (seconds after t = 0).
struct Ignition {
  PlanGeometry shape;
  double time = 0;
};

/// The ignition time of a feature: a number of seconds, a text holding one, or an ISO 8601
/// date-time (with [time] start); null or absent: 0.
double ignition_time(const CaseConfig& config, const AttributeValue& value, std::size_t feature) {
  const auto& file = config.region.ignitions;
  if (const auto* integer = std::get_if<std::int64_t>(&value)) return double(*integer);
  if (const auto* real = std::get_if<double>(&value)) {
    if (!std::isfinite(*real)) throw file_error(file, fmt::format("feature {}: ignition time {} is not finite", feature, *real));
    return *real;
  }
  if (const auto* text = std::get_if<std::string>(&value)) {
    double seconds = 0;
    const char* end = text->data() + text->size();
    if (auto [ptr, ec] = std::from_chars(text->data(), end, seconds); ec == std::errc() && ptr == end && std::isfinite(seconds))
      return seconds;
    const auto clock = parse_iso8601(*text);
    if (!clock)
      throw file_error(file, fmt::format("feature {}: ignition time '{}' is neither seconds nor an ISO 8601 date-time "
                                         "with its zone (e.g. 2026-07-14T15:30:00Z)",
                                         feature, *text));
    if (!config.time.start_seconds)
      throw file_error(file, fmt::format("feature {}: ignition time '{}' is a date-time, and the case gives no [time] "
                                         "start to count from",
                                         feature, *text));
    return *clock - *config.time.start_seconds;
  }
  return 0;
}

/// The features of [region] file, checked: a projected coordinate system (the DEM's when the
/// surface is one), a radius for points and lines, ignition times.
std::vector<Ignition> read_ignitions(const CaseConfig& config) {
  const auto& r = config.region;
  VectorLayer layer = read_vector_layer(r.ignitions);
  // In the surface's system (after its reprojection, when the case asks for one), as every layer.
  if (!config.surface.dem.empty()) {
    const SurfaceSource surface = case_surface_source(config);
    to_surface_crs(layer, r.ignitions, surface.crs, surface.reprojected_from, surface.file);
  }
  std::vector<Ignition> ignitions;
  for (std::size_t i = 0; i < layer.features.size(); ++i) {
    const VectorFeature& f = layer.features[i];
    if (f.geometry.empty()) continue;  // a feature without geometry ignites nothing
    if ((!f.geometry.points.empty() || !f.geometry.lines.empty()) && !(r.ignition_radius > 0))
      throw InputError(fmt::format("[region] radius: feature {} of {} has points or lines, which ignite disks and "
                                   "buffers of a radius: give radius > 0 (metres)",
                                   i + 1, r.ignitions.string()));
    const AttributeValue none;
    const double time = ignition_time(config, r.time_attribute.empty() ? none : f.attribute(r.time_attribute), i + 1);
    ignitions.push_back({f.geometry, time});
  }
  if (ignitions.empty()) throw file_error(r.ignitions, "no feature with a geometry: nothing ignites");
  return ignitions;
}

/// Distance in plan view to the ignited shape, negative inside: disks round points, buffers round
/// lines, polygons as they are.
double ignition_level_set(const PlanGeometry& shape, double radius, const Vec3& p) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& point : shape.points) d = std::min(d, std::hypot(p[0] - point[0], p[1] - point[1]) - radius);
  for (const auto& line : shape.lines) d = std::min(d, distance_to_path(line, p[0], p[1], false) - radius);
  for (const auto& polygon : shape.polygons) d = std::min(d, signed_distance_to_polygon(polygon, p[0], p[1]));
  return d;
}

}  // namespace

SurfaceMesh make_case_surface(const CaseConfig& config) {
  const auto& s = config.surface;
  switch (s.kind) {
    case SurfaceSpec::Kind::File:
      return read_mesh(s.file);
    case SurfaceSpec::Kind::Sphere:
      return make_sphere(s.sphere);
    case SurfaceSpec::Kind::Terrain:
      if (s.dem.empty()) return make_terrain(s.terrain);
      return make_terrain_from_grid(read_dem(s.dem, {.reproject = s.reproject}), {.h = s.terrain.h, .nodata = s.nodata});
    case SurfaceSpec::Kind::Plane:
      return make_plane(s.plane);
  }
  return {};
}

SurfaceSource case_surface_source(const CaseConfig& config) {
  const auto& s = config.surface;
  if (s.kind != SurfaceSpec::Kind::Terrain || s.dem.empty()) return {};
  DemCoordinates coordinates = dem_coordinates(s.dem, {.reproject = s.reproject});
  return {.file = s.dem, .crs = std::move(coordinates.crs), .reprojected_from = std::move(coordinates.reprojected_from)};
}

ScalarField initial_level_set(const CaseConfig& config, const SurfaceMesh& surface) {
  const auto& r = config.region;
  ScalarField phi(surface.n_vertices());
  switch (r.kind) {
    case RegionSpec::Kind::Refs:
      return {};
    case RegionSpec::Kind::Sol:
      return read_scalar_sol(r.sol, surface.n_vertices());
    case RegionSpec::Kind::Cap: {
      // Geodesic distance on a sphere of radius R: R·(polar angle − cap angle).
      // For a union, the distance to the union is the min of the distances (exact outside).
      for (auto v : surface.vertices()) {
        Vec3 p = surface.point(v) - r.center;
        double radius = p.norm();
        double value = std::numeric_limits<double>::infinity();
        for (const auto& [axis, angle] : r.caps) {
          double beta = std::atan2(cross(p, axis).norm(), dot(p, axis));
          value = std::min(value, radius * (beta - angle * std::numbers::pi / 180));
        }
        phi[v.idx()] = value;
      }
      return phi;
    }
    case RegionSpec::Kind::Balls: {
      // The Euclidean distance to the nearest ball's boundary (the run starts from the true signed
      // geodesic distance to the region this cuts).
      for (auto v : surface.vertices()) {
        const Vec3& p = surface.point(v);
        double d = std::numeric_limits<double>::infinity();
        for (const auto& [cx, cy, cz, radius] : r.balls) d = std::min(d, (p - Vec3(cx, cy, cz)).norm() - radius);
        phi[v.idx()] = d;
      }
      return phi;
    }
    case RegionSpec::Kind::Ignitions: {
      // G(0): the features igniting at t ≤ 0; the others join later (setup_case's additions).
      std::vector<Ignition> at_start;
      double first = std::numeric_limits<double>::infinity();
      for (auto& ignition : read_ignitions(config)) {
        first = std::min(first, ignition.time);
        if (ignition.time <= 0) at_start.push_back(std::move(ignition));
      }
      if (at_start.empty())
        throw file_error(r.ignitions, fmt::format("no feature ignites at t = 0 (the first at t = {} s): a run starts "
                                                  "burning; move [time] start to the first ignition",
                                                  first));
      for (auto v : surface.vertices()) {
        double d = std::numeric_limits<double>::infinity();
        for (const auto& ignition : at_start)
          d = std::min(d, ignition_level_set(ignition.shape, r.ignition_radius, surface.point(v)));
        phi[v.idx()] = d;
      }
      return phi;
    }
    case RegionSpec::Kind::Disks: {
      for (auto v : surface.vertices()) {
        const Vec3& p = surface.point(v);
        double d = std::numeric_limits<double>::infinity();
        for (const auto& [cx, cy, radius] : r.disks) d = std::min(d, std::hypot(p[0] - cx, p[1] - cy) - radius);
        phi[v.idx()] = d;
      }
      return phi;
    }
  }
  return phi;
}

std::shared_ptr<const ReferenceSurface> make_case_reference(const CaseConfig& config, const SurfaceMesh& surface) {
  if (config.surface.kind == SurfaceSpec::Kind::Sphere)
    return ReferenceSurface::sphere(config.surface.sphere.center, config.surface.sphere.radius);
  SurfaceMesh copy = surface;
  copy.garbage_collection();
  return std::make_shared<const ReferenceSurface>(copy);
}

CaseSetup setup_case(const CaseConfig& config) {
  CaseSetup setup;
  SurfaceMesh& mesh = setup.mesh;
  mesh = make_case_surface(config);
  mesh.garbage_collection();
  EvolutionOptions& options = setup.options;
  options.remesh = config.remesh;
  // One size for the whole run when none is given: T^0's resolution, taken before the cut (whose
  // small edges are not a resolution), as `bodyfit discretize` does.
  if (options.remesh.hmax <= 0) options.remesh.hmax = resolution_length(mesh);
  // A landscape has no sharp features: on steep terrain many lattice edges exceed the 45° dihedral
  // angle, and ridges detected there froze the remesher (minimum quality 0.06 instead of 0.6 on
  // the fire cases). Feature detection stays off for terrains unless [remesh] angle is given.
  if (config.surface.kind == SurfaceSpec::Kind::Terrain && !config.remesh_angle_given) options.remesh.feature_angle = 0;
  // For the same reason the changes are not held within hausd of the DEM's lattice (q_min 0.34 →
  // 0.14 and twice the remesh time on fire_one_disk when they are).
  if (config.surface.kind == SurfaceSpec::Kind::Terrain) options.remesh.check_distance_to_reference = false;
  options.remesh.reference = make_case_reference(config, mesh);
  // Every remesh of the run aims at these sizes: refuse a run whose meshes cannot fit.
  check_face_budget(estimate_remesh_faces(mesh, options.remesh),
                    config.remesh.hmax > 0 ? fmt::format("[remesh] hmax = {}", config.remesh.hmax)
                                           : std::string("[remesh] the default hmax (diagonal / 20)"));
  if (config.region.kind == RegionSpec::Kind::Refs) {
    label_from_refs(config, mesh);
    remesh(mesh, options.remesh);
  } else {
    mesh_initial_region(mesh, initial_level_set(config, mesh), config.discretize, options.remesh);
  }
  setup.h = options.remesh.hmax;
  options.dt = config.time.dt > 0 ? config.time.dt : config.time.cfl * setup.h;
  options.final_time = config.time.final_time;
  options.max_cfl = config.time.max_cfl;
  options.narrow_band = config.time.narrow_band;
  options.keep_crossings = config.time.keep_crossings;
  options.compose_substeps = config.time.compose_substeps;
  options.max_substeps = config.time.max_substeps;
  options.max_rejections = config.time.max_rejections;
  options.cfl_length = setup.h;
  options.max_iterations = config.time.iterations;
  check_step_count(config.time, options.dt, mesh.n_faces());
  options.distance = config.distance;
  options.advection = config.advection;
  options.discretize = config.discretize;
  options.height_field = config.surface.height_field();
  options.clock_start = config.time.start_seconds;
  if (config.region.kind == RegionSpec::Kind::Ignitions)
    for (auto& ignition : read_ignitions(config))
      if (ignition.time > 0)
        options.additions.push_back(
            {.time = ignition.time,
             .level_set = [shape = std::move(ignition.shape), radius = config.region.ignition_radius](const Vec3& p) {
               return ignition_level_set(shape, radius, p);
             }});
  return setup;
}

void label_from_refs(const CaseConfig& config, SurfaceMesh& surface) {
  const auto& refs = config.region.refs;
  std::size_t inside = 0;
  for (auto f : surface.faces()) {
    bool in = std::find(refs.begin(), refs.end(), surface.region(f)) != refs.end();
    surface.region(f) = in ? kInside : kOutside;
    inside += in;
  }
  if (inside == 0) throw InputError(fmt::format("[region] refs: no face of the surface carries refs [{}]", fmt::join(refs, ", ")));
  update_interface_from_regions(surface);
}

}  // namespace bodyfit
