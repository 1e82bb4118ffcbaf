// Reading a run case: --set overrides, then every table validated through bodyfit::Parameters
// into a CaseConfig. Setting up the run from it is case_setup.cpp.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/parameters.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string_view>

namespace bodyfit {
namespace {

// [ensemble] is read by `bodyfit ensemble` (ensemble.hpp); a run of the case leaves it aside.
const std::vector<std::string> kSections{"surface",    "region",     "model",  "time",   "distance",
                                         "advection", "discretize", "remesh", "output", "ensemble"};

const Range kPositive{.min = 0, .min_exclusive = true};

Vec3 to_vec3(const std::vector<double>& v) { return Vec3(v[0], v[1], v[2]); }

/// An int option read as a TOML integer: beyond the int range means "as many as possible" (no run
/// gets there), without the wrap-around of a plain cast.
int clamp_to_int(std::int64_t value) {
  return int(std::clamp<std::int64_t>(value, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
}

/// A polar angle in degrees, strictly between the pole and the antipode.
double check_angle(const Parameters& p, std::string_view key, double degrees) {
  if (!(degrees > 0 && degrees < 180)) p.fail(key, fmt::format("must be in (0, 180) degrees (got {})", degrees));
  return degrees;
}

void parse_surface(const toml::table& table, const std::filesystem::path& sourceless, SurfaceSpec& out) {
  if (!table.contains("surface")) throw InputError("missing table [surface] (file = ... or generator = ...)");
  Parameters p(table["surface"].as_table(), "surface");
  const bool has_file = p.has("file");
  const bool has_generator = p.has("generator");
  p.accept("file");
  p.accept("generator");
  if (has_file == has_generator) p.fail("give exactly one of 'file' and 'generator'");
  if (has_file) {
    out.kind = SurfaceSpec::Kind::File;
    out.file = p.path("file", "", sourceless);
    p.forbid({"faces", "radius", "h", "extent", "seed", "dem", "nodata", "reproject", "size", "max_height", "feature_size"},
             "to a surface read from a file");
  } else {
    std::string g = p.choice("generator", "sphere", {"sphere", "terrain", "plane"});
    if (g == "sphere") {
      out.kind = SurfaceSpec::Kind::Sphere;
      out.sphere.radius = p.number("radius", 1.0, kPositive);
      const std::int64_t faces = p.integer("faces", 0, 20);
      const double h = p.number("h", 0, kPositive);
      if ((faces > 0) == (h > 0)) p.fail("sphere: give exactly one of 'faces' and 'h'");
      // Mean edge h: 4πR² ≈ F·(√3/4)h². Refused here, before the count is rounded, when too many.
      const double count = faces > 0 ? double(faces)
                                      : faces_for_edge_length(4 * std::numbers::pi * out.sphere.radius * out.sphere.radius, h);
      check_face_budget(count, faces > 0 ? fmt::format("[surface] faces = {}", faces)
                                         : fmt::format("[surface] h = {} on a sphere of radius {}", h, out.sphere.radius));
      out.sphere.faces = std::size_t(std::llround(std::min(count, 1e18)));  // 1e18: only with --max-faces 0
      p.forbid({"extent", "seed", "dem", "nodata", "reproject", "size", "max_height", "feature_size"},
               "to generator 'sphere'");
    } else if (g == "terrain") {
      out.kind = SurfaceSpec::Kind::Terrain;
      out.terrain.extent = p.number("extent", out.terrain.extent, kPositive);
      out.terrain.h = p.number("h", out.terrain.h, kPositive);
      // Any integer seeds the landscape (a negative one wraps around).
      out.terrain.seed = std::uint64_t(p.integer("seed", std::int64_t(out.terrain.seed)));
      out.terrain.max_height = p.number("max_height", out.terrain.max_height);
      out.terrain.feature_size = p.number("feature_size", out.terrain.feature_size, kPositive);
      out.dem = p.path("dem", "", sourceless);
      if (out.dem.empty()) {
        p.forbid({"nodata", "reproject"}, "to a procedural terrain (no 'dem')");
      } else {
        out.nodata = p.choice("nodata", "hole", {"hole", "fill"}) == "fill" ? NodataMode::fill : NodataMode::hole;
        out.reproject = p.choice("reproject", "none", {"none", "utm"}) == "utm" ? Reprojection::utm : Reprojection::none;
      }
      p.forbid({"faces", "radius", "size"}, "to generator 'terrain'");
    } else {
      out.kind = SurfaceSpec::Kind::Plane;
      out.plane.size = p.number("size", out.plane.size, kPositive);
      out.plane.h = p.number("h", out.plane.h, kPositive);
      p.forbid({"faces", "radius", "extent", "seed", "dem", "nodata", "reproject", "max_height", "feature_size"},
               "to generator 'plane'");
    }
  }
  p.reject_unknown();
}

void parse_region(const toml::table& table, const std::filesystem::path& sourceless, RegionSpec& out) {
  if (!table.contains("region")) throw InputError("missing table [region] (shape = refs|sol|cap|disks)");
  Parameters p(table["region"].as_table(), "region");
  if (!p.has("shape")) p.fail("missing key 'shape' (refs, sol, cap or disks)");
  const std::string shape = p.choice("shape", "", {"refs", "sol", "cap", "disks", "balls", "ignitions"});
  if (shape == "refs") {
    out.kind = RegionSpec::Kind::Refs;
    // Integers that fit an int (converting 1e300 to int was undefined: found by fuzz_case).
    const auto refs = p.numbers("refs", {}, std::nullopt,
                                {.min = std::numeric_limits<int>::min(), .max = std::numeric_limits<int>::max()});
    if (p.has("refs")) {
      out.refs.clear();
      for (double r : refs) {
        if (r != std::trunc(r)) p.fail("refs", fmt::format("{} is not an integer", r));
        out.refs.push_back(int(r));
      }
    }
    p.forbid({"sol", "axis", "angle", "axes", "angles", "center", "centers", "radii"}, "to shape 'refs'");
  } else if (shape == "sol") {
    out.kind = RegionSpec::Kind::Sol;
    p.accept("sol");
    if (!p.has("sol")) p.fail("shape 'sol': missing key 'sol' (the φ file)");
    out.sol = p.path("sol", "", sourceless);
    p.forbid({"refs", "axis", "angle", "axes", "angles", "center", "centers", "radii"}, "to shape 'sol'");
  } else if (shape == "cap") {
    out.kind = RegionSpec::Kind::Cap;
    if (auto center = p.numbers("center", {}, 3); !center.empty()) out.center = to_vec3(center);
    // Both spellings are known keys of a cap, whichever is used (for the suggestions).
    for (const char* key : {"axis", "angle", "axes", "angles"}) p.accept(key);
    if (p.has("axes") || p.has("angles")) {
      // A union of caps.
      if (p.has("axis") || p.has("angle")) p.fail("give either axis/angle or axes/angles");
      if (!p.has("axes")) p.fail("shape 'cap': 'axes' = [[x, y, z], ...] must go with 'angles'");
      const auto axes = p.number_arrays("axes", 3);
      const auto angles = p.numbers("angles", {});
      if (axes.size() != angles.size() || angles.empty())
        p.fail(fmt::format("axes and angles: {} axes but {} angles", axes.size(), angles.size()));
      for (std::size_t i = 0; i < angles.size(); ++i) {
        Vec3 axis = to_vec3(axes[i]);
        if (!(axis.norm() > 0)) p.fail("axes", fmt::format("axis {} must not be zero", i + 1));
        out.caps.emplace_back(axis.normalized(), check_angle(p, "angles", angles[i]));
      }
    } else {
      if (auto axis = p.numbers("axis", {}, 3); !axis.empty()) out.axis = to_vec3(axis);
      if (!(out.axis.norm() > 0)) p.fail("axis", "must not be zero");
      out.axis.normalize();
      if (!p.has("angle")) p.fail("shape 'cap': missing key 'angle' (polar angle in degrees)");
      out.angle = check_angle(p, "angle", p.number("angle", out.angle));
      out.caps.emplace_back(out.axis, out.angle);
    }
    p.forbid({"refs", "sol", "centers", "radii"}, "to shape 'cap'");
  } else if (shape == "ignitions") {
    out.kind = RegionSpec::Kind::Ignitions;
    p.accept("file");
    if (!p.has("file")) p.fail("shape 'ignitions': missing key 'file' (a vector layer: .geojson, .shp, .gpkg)");
    out.ignitions = p.path("file", "", sourceless);
    out.ignition_radius = p.number("radius", 0, {.min = 0});
    out.time_attribute = p.string("time_attribute", "");
    p.forbid({"refs", "sol", "axis", "angle", "axes", "angles", "center", "centers", "radii"}, "to shape 'ignitions'");
  } else if (shape == "balls") {
    out.kind = RegionSpec::Kind::Balls;
    const auto centers = p.number_arrays("centers", 3);
    const auto radii = p.numbers("radii", {}, std::nullopt, kPositive);
    if (!p.has("centers") || radii.empty()) p.fail("shape 'balls': needs 'centers' = [[x, y, z], ...] and 'radii'");
    if (centers.size() != radii.size())
      p.fail(fmt::format("centers and radii: {} centres but {} radii", centers.size(), radii.size()));
    for (std::size_t i = 0; i < radii.size(); ++i)
      out.balls.push_back({centers[i][0], centers[i][1], centers[i][2], radii[i]});
    p.forbid({"refs", "sol", "axis", "angle", "axes", "angles", "center"}, "to shape 'balls'");
  } else {
    out.kind = RegionSpec::Kind::Disks;
    const auto centers = p.number_arrays("centers", 2);
    const auto radii = p.numbers("radii", {}, std::nullopt, kPositive);
    if (!p.has("centers") || radii.empty()) p.fail("shape 'disks': needs 'centers' = [[x, y], ...] and 'radii'");
    if (centers.size() != radii.size())
      p.fail(fmt::format("centers and radii: {} centres but {} radii", centers.size(), radii.size()));
    for (std::size_t i = 0; i < radii.size(); ++i) out.disks.push_back({centers[i][0], centers[i][1], radii[i]});
    p.forbid({"refs", "sol", "axis", "angle", "axes", "angles", "center"}, "to shape 'disks'");
  }
  p.reject_unknown();
}

/// [model]: the plugin's name; its other keys are the model's, checked by the plugin itself.
void parse_model(const toml::table& table, CaseConfig& config) {
  const auto* model = table["model"].as_table();
  if (!model) throw InputError("missing table [model] (name = \"conormal\", ...)");
  Parameters p(*model, "model");
  if (!p.has("name")) p.fail("missing key 'name' (the velocity model, e.g. \"conormal\")");
  config.model = p.string("name", "");
  config.model_parameters = *model;
  config.model_parameters.erase("name");
}

void parse_time(const toml::table& table, TimeSpec& out) {
  if (!table.contains("time")) throw InputError("missing table [time] (dt or cfl, final_time or iterations)");
  Parameters p(table["time"].as_table(), "time");
  out.dt = p.number("dt", 0, kPositive);
  out.cfl = p.number("cfl", 0, kPositive);
  out.max_cfl = p.number("max_cfl", 0, kPositive);
  out.narrow_band = p.boolean("narrow_band", out.narrow_band);
  out.keep_crossings = p.boolean("keep_crossings", out.keep_crossings);
  out.compose_substeps = p.boolean("compose_substeps", out.compose_substeps);
  out.max_substeps = long(p.integer("max_substeps", out.max_substeps, 0));
  out.final_time = p.number("final_time", out.final_time, kPositive);
  out.iterations = long(p.integer("iterations", -1, 0));
  out.max_steps = long(p.integer("max_steps", out.max_steps, 0));
  out.max_rejections = clamp_to_int(p.integer("max_rejections", out.max_rejections, 0));
  out.start = p.string("start", "");
  if (p.has("start")) {
    out.start_seconds = parse_iso8601(out.start);
    if (!out.start_seconds)
      p.fail("start", fmt::format("'{}' is not an ISO 8601 date-time with its zone (e.g. \"2026-07-14T13:00:00Z\", or "
                                  "\"2026-07-14T15:00:00+02:00\")",
                                  out.start));
  }
  p.reject_unknown();  // first: a misspelt key often explains a missing one
  if ((out.dt > 0) == (out.cfl > 0)) p.fail("give exactly one of 'dt' and 'cfl'");
  if (!p.has("final_time") && !p.has("iterations")) p.fail("give 'final_time' or 'iterations' (or both)");
}

void parse_stages(const toml::table& table, CaseConfig& config) {
  {
    Parameters p(table["distance"].as_table(), "distance");
    config.distance.narrow_band = p.number("narrow_band", config.distance.narrow_band, kPositive);
    p.reject_unknown();
  }
  {
    Parameters p(table["advection"].as_table(), "advection");
    auto& out = config.advection;
    const std::int64_t rk_order = p.integer("rk_order", out.rk_order);
    if (rk_order != 2 && rk_order != 4) p.fail("rk_order", fmt::format("must be 2 or 4 (got {})", rk_order));
    out.rk_order = int(rk_order);
    out.max_cells_per_substep = p.number("max_cells_per_substep", out.max_cells_per_substep, kPositive);
    out.max_substeps = p.number("max_substeps", out.max_substeps, {.min = 0});
    out.steps = clamp_to_int(p.integer("steps", out.steps, 1));
    out.gradient_correction = p.boolean("gradient_correction", out.gradient_correction);
    p.reject_unknown();
  }
  {
    Parameters p(table["discretize"].as_table(), "discretize");
    auto& out = config.discretize;
    // Snapping by half an edge or more would merge the two ends of an edge.
    const Range snap{.min = 0, .max = 0.5, .max_exclusive = true};
    out.snap_ratio = p.number("snap_ratio", out.snap_ratio, snap);
    out.fixed_snap_ratio = p.number("fixed_snap_ratio", out.fixed_snap_ratio, snap);
    out.speck_area = p.number("speck_area", out.speck_area, {.min = 0});
    out.drop_detached = p.boolean("drop_detached", out.drop_detached);
    out.hermite_crossings = p.boolean("hermite_crossings", out.hermite_crossings);
    out.fitted_slopes = p.boolean("fitted_slopes", out.fitted_slopes);
    p.reject_unknown();
  }
  {
    Parameters p(table["remesh"].as_table(), "remesh");
    auto& out = config.remesh;
    out.hmin = p.number("hmin", out.hmin, kPositive);
    out.hmax = p.number("hmax", out.hmax, kPositive);
    out.hausd = p.number("hausd", out.hausd, kPositive);
    out.hausd_interface = p.number("hausd_interface", out.hausd_interface, kPositive);
    out.hgrad = p.number("hgrad", out.hgrad, {.min = 1});
    config.remesh_angle_given = p.has("angle");
    out.feature_angle = p.number("angle", out.feature_angle);
    out.max_passes = clamp_to_int(p.integer("max_passes", out.max_passes, 0));  // 0: no cap
    out.incremental = p.boolean("incremental", out.incremental);
    if (out.hmin > 0 && out.hmax > 0 && out.hmin > out.hmax)
      p.fail("hmin", fmt::format("{} must not exceed hmax = {}", out.hmin, out.hmax));
    p.reject_unknown();
  }
}

void parse_output(const toml::table& table, OutputSpec& out) {
  Parameters p(table["output"].as_table(), "output");
  out.vtu_every = clamp_to_int(p.integer("vtu_every", out.vtu_every, 0));  // 0: never
  out.png_every = clamp_to_int(p.integer("png_every", out.png_every, 0));
  out.field = p.string("field", out.field);
  out.view = p.choice("view", out.view, {"iso", "top", "front"});
  if (auto size = p.numbers("size", {}, 2, {.min = 16, .max = 8192}); !size.empty())
    out.width = int(size[0]), out.height = int(size[1]);
  out.checkpoint_every = clamp_to_int(p.integer("checkpoint_every", out.checkpoint_every, 0));
  out.checkpoint_seconds = p.number("checkpoint_seconds", out.checkpoint_seconds, {.min = 0});
  out.grid_format = p.choice("grid_format", out.grid_format, {"tif", "asc"});
  if (out.grid_format == "tif" && !config::have_gdal)
    p.fail("grid_format", "GeoTIFF needs GDAL, and bodyfit was built without it: give \"asc\"");
  p.reject_unknown();
}

}  // namespace

void apply_override(toml::table& table, const std::string& assignment) {
  auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set '{}': expected key=value (e.g. time.dt=0.05)", assignment));
  std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string part; std::getline(ss, part, '.');) {
    if (part.empty()) throw InputError(fmt::format("--set '{}': empty component in key '{}'", assignment, path));
    parts.push_back(part);
  }
  toml::table* current = &table;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    auto* child = current->get(parts[i]);
    if (!child) {
      current->insert(parts[i], toml::table{});
      child = current->get(parts[i]);
    }
    if (!child->is_table())
      throw InputError(fmt::format("--set '{}': '{}' is not a table", assignment, parts[i]));
    current = child->as_table();
  }
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + text);
  } catch (const toml::parse_error&) {
    parsed = toml::table{};
    parsed.insert("v", text);  // a bare word: a string
  }
  current->insert_or_assign(parts.back(), *parsed.get("v"));
}

CaseConfig parse_case(const toml::table& table, const std::filesystem::path& base_dir) {
  return parse_case(table, base_dir, base_dir);
}

CaseConfig parse_case(const toml::table& table, const std::filesystem::path& base_dir,
                      const std::filesystem::path& sourceless) {
  CaseConfig config;
  config.base_dir = base_dir;
  config.effective = table;
  for (auto&& [key, value] : table) {
    std::string k(key.str());
    if (std::find(kSections.begin(), kSections.end(), k) == kSections.end()) {
      std::string hint = closest_match(k, kSections);
      throw InputError(fmt::format("{}unknown table [{}]{}", location_of(value), k,
                                   hint.empty() ? "" : fmt::format("; did you mean '{}'?", hint)));
    }
    if (!value.is_table()) throw InputError(fmt::format("{}'{}' must be a table [{}]", location_of(value), k, k));
  }
  parse_surface(table, sourceless, config.surface);
  parse_region(table, sourceless, config.region);
  parse_model(table, config);
  parse_time(table, config.time);
  parse_stages(table, config);
  parse_output(table, config.output);
  return config;
}

toml::table read_case_table(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  toml::table table;
  if (std::ifstream probe(file); !probe)  // toml++ would say "line 0: File could not be opened"
    throw file_error(file, fmt::format("cannot open for reading ({})", std::strerror(errno)));
  try {
    table = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw file_error(file, long(e.source().begin.line), std::string(e.description()));
  }
  for (const auto& o : overrides) apply_override(table, o);
  return table;
}

CaseConfig read_case(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  toml::table table = read_case_table(file, overrides);
  try {
    // The case file's values carry their source; a --set value has none and is relative to the
    // working directory, where the command line was typed.
    CaseConfig config = parse_case(table, file.parent_path(), std::filesystem::path());
    config.file = file;
    // Moved, not copied: toml++ copies drop the source file of each value, which
    // Parameters::path needs to resolve a model's file names against the case file.
    config.model_parameters = std::move(*table["model"].as_table());
    config.model_parameters.erase("name");
    return config;
  } catch (const InputError& e) {
    // A value from the file is already located ("case.toml:12: "); one from --set is not.
    if (std::string_view(e.what()).starts_with(file.string() + ":")) throw;
    throw file_error(file, e.what());
  }
}

}  // namespace bodyfit
