#include <bodyfit/case_config.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/projection.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace bodyfit {
namespace {

std::string where(const toml::node& node) {
  const auto& source = node.source();
  if (source.begin.line == 0) return "";
  return fmt::format(" (line {})", source.begin.line);
}

/// One table of the case: reads typed keys and remembers which were read, so that the rest can be
/// reported as unknown with a suggestion.
class Section {
 public:
  Section(const toml::table* table, std::string name) : table_(table), name_(std::move(name)) {}

  bool has(const std::string& key) {
    known_.push_back(key);
    return table_ && table_->contains(key);
  }
  const toml::node* node(const std::string& key) {
    known_.push_back(key);
    return table_ ? table_->get(key) : nullptr;
  }
  [[noreturn]] void type_error(const std::string& key, const char* expected) const {
    throw InputError(fmt::format("[{}] {}: expected {}{}", name_, key, expected, where(*table_->get(key))));
  }
  double number(const std::string& key, double fallback) {
    const auto* n = node(key);
    if (!n) return fallback;
    if (auto v = n->value<double>(); v && (n->is_floating_point() || n->is_integer())) return *v;
    type_error(key, "a number");
  }
  double positive(const std::string& key, double fallback) {
    double v = number(key, fallback);
    if (has(key) && !(v > 0)) throw InputError(fmt::format("[{}] {}: must be > 0 (got {})", name_, key, v));
    return v;
  }
  long integer(const std::string& key, long fallback) {
    const auto* n = node(key);
    if (!n) return fallback;
    if (!n->is_integer()) type_error(key, "an integer");
    return static_cast<long>(*n->value<std::int64_t>());
  }
  bool boolean(const std::string& key, bool fallback) {
    const auto* n = node(key);
    if (!n) return fallback;
    if (!n->is_boolean()) type_error(key, "true or false");
    return *n->value<bool>();
  }
  std::string string(const std::string& key, const std::string& fallback) {
    const auto* n = node(key);
    if (!n) return fallback;
    if (!n->is_string()) type_error(key, "a string");
    return *n->value<std::string>();
  }
  std::string choice(const std::string& key, const std::vector<std::string>& choices, const std::string& fallback) {
    std::string v = string(key, fallback);
    if (std::find(choices.begin(), choices.end(), v) != choices.end()) return v;
    std::string hint = closest_match(v, choices);
    throw InputError(fmt::format("[{}] {}: unknown value '{}'{}; expected one of: {}", name_, key, v,
                                 hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint),
                                 fmt::join(choices, ", ")));
  }
  std::vector<double> numbers(const std::string& key, std::size_t size_or_zero) {
    const auto* n = node(key);
    if (!n) return {};
    const auto* array = n->as_array();
    if (!array) type_error(key, "an array of numbers");
    std::vector<double> out;
    for (const auto& item : *array) {
      auto v = item.value<double>();
      if (!v) type_error(key, "an array of numbers");
      out.push_back(*v);
    }
    if (size_or_zero && out.size() != size_or_zero)
      throw InputError(fmt::format("[{}] {}: expected {} numbers, got {}{}", name_, key, size_or_zero, out.size(),
                                   where(*n)));
    return out;
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(fmt::format("[{}] {}", name_, what)); }

  /// Every key that was not read is an error.
  void check_unknown() const {
    if (!table_) return;
    for (auto&& [key, value] : *table_) {
      std::string k(key.str());
      if (std::find(known_.begin(), known_.end(), k) != known_.end()) continue;
      std::string hint = closest_match(k, known_);
      throw InputError(fmt::format("unknown key '{}' in [{}]{}{}", k, name_, where(value),
                                   hint.empty() ? "" : fmt::format("; did you mean '{}'?", hint)));
    }
  }
  /// Keys read only for some variants: an error when present for the others.
  void forbid(const std::vector<std::string>& keys, const std::string& reason) const {
    if (!table_) return;
    for (const auto& k : keys)
      if (table_->contains(k)) fail(fmt::format("{}: does not apply {}", k, reason));
  }

 private:
  const toml::table* table_;
  std::string name_;
  std::vector<std::string> known_;
};

const std::vector<std::string> kSections{"surface",    "region", "model",  "time",  "distance",
                                         "advection", "discretize", "remesh", "output"};

Vec3 to_vec3(const std::vector<double>& v) { return Vec3(v[0], v[1], v[2]); }

/// A flat square [-size/2, size/2]² at z = 0 triangulated with rows of near-equilateral triangles.
SurfaceMesh make_plane(double size, double h) {
  SurfaceMesh mesh;
  const double row_height = h * std::sqrt(3.0) / 2;
  const int rows = std::max(1, int(std::lround(size / row_height)));
  const int cols = std::max(1, int(std::lround(size / h)));
  const double dy = size / rows, dx = size / cols;
  std::vector<std::vector<VertexHandle>> grid(rows + 1);
  for (int r = 0; r <= rows; ++r) {
    // Odd rows are shifted by half a cell (their end points stay on the boundary).
    const bool odd = r % 2 == 1;
    const double y = -size / 2 + r * dy;
    grid[r].push_back(mesh.add_vertex(Vec3(-size / 2, y, 0)));
    for (int c = 0; c < cols - (odd ? 1 : 0); ++c) {
      double x = -size / 2 + (c + (odd ? 0.5 : 1.0)) * dx;
      if (!odd && c == cols - 1) x = size / 2;
      grid[r].push_back(mesh.add_vertex(Vec3(x, y, 0)));
    }
    if (odd) grid[r].push_back(mesh.add_vertex(Vec3(size / 2, y, 0)));
  }
  // Row r (even: cols+1 points, odd: cols+2 points); zig-zag between consecutive rows.
  for (int r = 0; r < rows; ++r) {
    const auto& a = grid[r];
    const auto& b = grid[r + 1];
    std::size_t i = 0, j = 0;
    while (i + 1 < a.size() || j + 1 < b.size()) {
      // Advance on the row whose next point is further behind.
      bool advance_a;
      if (i + 1 >= a.size()) advance_a = false;
      else if (j + 1 >= b.size()) advance_a = true;
      else advance_a = mesh.point(a[i + 1])[0] <= mesh.point(b[j + 1])[0];
      if (advance_a) {
        mesh.add_face(a[i], a[i + 1], b[j]);
        ++i;
      } else {
        mesh.add_face(a[i], b[j + 1], b[j]);
        ++j;
      }
    }
  }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  return mesh;
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
  CaseConfig config;
  config.base_dir = base_dir;
  config.effective = table;
  for (auto&& [key, value] : table) {
    std::string k(key.str());
    if (std::find(kSections.begin(), kSections.end(), k) == kSections.end()) {
      std::string hint = closest_match(k, kSections);
      throw InputError(fmt::format("unknown table [{}]{}{}", k, where(value),
                                   hint.empty() ? "" : fmt::format("; did you mean '{}'?", hint)));
    }
    if (!value.is_table()) throw InputError(fmt::format("'{}' must be a table [{}]{}", k, k, where(value)));
  }
  auto section = [&](const char* name) { return Section(table[name].as_table(), name); };
  auto resolve = [&](const std::string& p) { return p.empty() ? std::filesystem::path() : base_dir / p; };

  {  // [surface]
    Section s = section("surface");
    if (!table.contains("surface")) throw InputError("missing table [surface] (file = ... or generator = ...)");
    const bool has_file = s.has("file");
    const bool has_generator = s.has("generator");
    if (has_file == has_generator) s.fail("give exactly one of 'file' and 'generator'");
    auto& out = config.surface;
    if (has_file) {
      out.kind = SurfaceSpec::Kind::File;
      out.file = resolve(s.string("file", ""));
      s.forbid({"faces", "radius", "h", "extent", "seed", "dem", "size", "max_height", "feature_size"},
               "to a surface read from a file");
    } else {
      std::string g = s.choice("generator", {"sphere", "terrain", "plane"}, "sphere");
      if (g == "sphere") {
        out.kind = SurfaceSpec::Kind::Sphere;
        out.sphere.radius = s.positive("radius", 1.0);
        long faces = s.integer("faces", 0);
        double h = s.positive("h", 0);
        if ((faces > 0) == (h > 0)) s.fail("sphere: give exactly one of 'faces' and 'h'");
        if (s.has("faces") && faces < 20) s.fail("faces: must be ≥ 20");
        // Mean edge h: 4πR² ≈ F·(√3/4)h².
        out.sphere.faces = faces > 0 ? std::size_t(faces)
                                     : std::size_t(std::lround(16 * std::numbers::pi * out.sphere.radius *
                                                               out.sphere.radius / (std::sqrt(3.0) * h * h)));
        s.forbid({"extent", "seed", "dem", "size", "max_height", "feature_size"}, "to generator 'sphere'");
      } else if (g == "terrain") {
        out.kind = SurfaceSpec::Kind::Terrain;
        out.terrain.extent = s.positive("extent", out.terrain.extent);
        out.terrain.h = s.positive("h", out.terrain.h);
        out.terrain.seed = std::uint64_t(s.integer("seed", long(out.terrain.seed)));
        out.terrain.max_height = s.number("max_height", out.terrain.max_height);
        out.terrain.feature_size = s.positive("feature_size", out.terrain.feature_size);
        out.dem = resolve(s.string("dem", ""));
        s.forbid({"faces", "radius", "size"}, "to generator 'terrain'");
      } else {
        out.kind = SurfaceSpec::Kind::Plane;
        out.plane_size = s.positive("size", out.plane_size);
        out.plane_h = s.positive("h", out.plane_h);
        s.forbid({"faces", "radius", "extent", "seed", "dem", "max_height", "feature_size"}, "to generator 'plane'");
      }
    }
    s.check_unknown();
  }
  {  // [region]
    Section s = section("region");
    if (!table.contains("region")) throw InputError("missing table [region] (shape = refs|sol|cap|disks)");
    auto& out = config.region;
    std::string shape = s.choice("shape", {"refs", "sol", "cap", "disks"}, "");
    if (shape == "refs") {
      out.kind = RegionSpec::Kind::Refs;
      if (s.has("refs")) {
        out.refs.clear();
        for (double r : s.numbers("refs", 0)) out.refs.push_back(int(r));
      }
      s.forbid({"sol", "axis", "angle", "axes", "angles", "center", "centers", "radii"}, "to shape 'refs'");
    } else if (shape == "sol") {
      out.kind = RegionSpec::Kind::Sol;
      if (!s.has("sol")) s.fail("shape 'sol': missing key 'sol' (the φ file)");
      out.sol = resolve(s.string("sol", ""));
      s.forbid({"refs", "axis", "angle", "axes", "angles", "center", "centers", "radii"}, "to shape 'sol'");
    } else if (shape == "cap") {
      out.kind = RegionSpec::Kind::Cap;
      if (auto center = s.numbers("center", 3); !center.empty()) out.center = to_vec3(center);
      if (s.has("axes") || s.has("angles")) {
        // A union of caps.
        if (s.has("axis") || s.has("angle")) s.fail("give either axis/angle or axes/angles");
        const auto* axes_node = s.node("axes");
        auto angles = s.numbers("angles", 0);
        const auto* axes = axes_node ? axes_node->as_array() : nullptr;
        if (!axes) s.fail("shape 'cap': 'axes' = [[x, y, z], ...] must go with 'angles'");
        if (axes->size() != angles.size() || angles.empty())
          s.fail(fmt::format("axes and angles: {} axes but {} angles", axes->size(), angles.size()));
        for (std::size_t i = 0; i < angles.size(); ++i) {
          const auto* a = (*axes)[i].as_array();
          if (!a || a->size() != 3) s.type_error("axes", "an array of [x, y, z] axes");
          Vec3 axis;
          for (int k = 0; k < 3; ++k) {
            auto c = (*a)[std::size_t(k)].value<double>();
            if (!c) s.type_error("axes", "an array of [x, y, z] axes");
            axis[k] = *c;
          }
          if (!(axis.norm() > 0)) s.fail("axes: must not be zero");
          if (!(angles[i] > 0 && angles[i] < 180)) s.fail("angles: each must be in (0, 180) degrees");
          out.caps.emplace_back(axis.normalized(), angles[i]);
        }
      } else {
        if (auto axis = s.numbers("axis", 3); !axis.empty()) out.axis = to_vec3(axis);
        if (!(out.axis.norm() > 0)) s.fail("axis: must not be zero");
        out.axis.normalize();
        if (!s.has("angle")) s.fail("shape 'cap': missing key 'angle' (polar angle in degrees)");
        out.angle = s.number("angle", 45);
        if (!(out.angle > 0 && out.angle < 180)) s.fail("angle: must be in (0, 180) degrees");
        out.caps.emplace_back(out.axis, out.angle);
      }
      s.forbid({"refs", "sol", "centers", "radii"}, "to shape 'cap'");
    } else {
      out.kind = RegionSpec::Kind::Disks;
      const auto* centers_node = s.node("centers");
      auto radii = s.numbers("radii", 0);
      if (!centers_node || radii.empty()) s.fail("shape 'disks': needs 'centers' = [[x, y], ...] and 'radii'");
      const auto* centers = centers_node->as_array();
      if (!centers) s.type_error("centers", "an array of [x, y] pairs");
      if (centers->size() != radii.size())
        s.fail(fmt::format("centers and radii: {} centres but {} radii", centers->size(), radii.size()));
      for (std::size_t i = 0; i < radii.size(); ++i) {
        const auto* pair = (*centers)[i].as_array();
        if (!pair || pair->size() != 2 || !(*pair)[0].value<double>() || !(*pair)[1].value<double>())
          s.type_error("centers", "an array of [x, y] pairs");
        if (!(radii[i] > 0)) s.fail("radii: must be > 0");
        out.disks.push_back({*(*pair)[0].value<double>(), *(*pair)[1].value<double>(), radii[i]});
      }
      s.forbid({"refs", "sol", "axis", "angle", "axes", "angles", "center"}, "to shape 'disks'");
    }
    s.check_unknown();
  }
  {  // [model]
    const auto* model = table["model"].as_table();
    if (!model) throw InputError("missing table [model] (name = \"conormal\", ...)");
    const auto* name = model->get("name");
    if (!name) throw InputError("[model] missing key 'name' (the velocity model, e.g. \"conormal\")");
    if (!name->is_string()) throw InputError(fmt::format("[model] name: expected a string{}", where(*name)));
    config.model = *name->value<std::string>();
    config.model_parameters = *model;
    config.model_parameters.erase("name");
  }
  {  // [time]
    Section s = section("time");
    if (!table.contains("time")) throw InputError("missing table [time] (dt or cfl, final_time or iterations)");
    auto& out = config.time;
    out.dt = s.positive("dt", 0);
    out.cfl = s.positive("cfl", 0);
    out.max_cfl = s.positive("max_cfl", 0);
    out.final_time = s.positive("final_time", out.final_time);
    out.iterations = s.integer("iterations", -1);
    s.check_unknown();  // first: a misspelt key often explains a missing one
    if ((out.dt > 0) == (out.cfl > 0)) s.fail("give exactly one of 'dt' and 'cfl'");
    if (s.has("iterations") && out.iterations < 0) s.fail("iterations: must be ≥ 0");
    if (!s.has("final_time") && !s.has("iterations")) s.fail("give 'final_time' or 'iterations' (or both)");
  }
  {  // [distance]
    Section s = section("distance");
    config.distance.narrow_band = s.positive("narrow_band", config.distance.narrow_band);
    s.check_unknown();
  }
  {  // [advection]
    Section s = section("advection");
    auto& out = config.advection;
    out.rk_order = int(s.integer("rk_order", out.rk_order));
    if (out.rk_order != 2 && out.rk_order != 4) s.fail("rk_order: must be 2 or 4");
    out.max_cells_per_substep = s.positive("max_cells_per_substep", out.max_cells_per_substep);
    out.steps = int(s.integer("steps", out.steps));
    if (out.steps < 1) s.fail("steps: must be ≥ 1");
    out.gradient_correction = s.boolean("gradient_correction", out.gradient_correction);
    s.check_unknown();
  }
  {  // [discretize]
    Section s = section("discretize");
    config.discretize.snap_ratio = s.number("snap_ratio", config.discretize.snap_ratio);
    if (!(config.discretize.snap_ratio >= 0 && config.discretize.snap_ratio < 0.5))
      s.fail("snap_ratio: must be in [0, 0.5)");
    config.discretize.fixed_snap_ratio = s.number("fixed_snap_ratio", config.discretize.fixed_snap_ratio);
    if (!(config.discretize.fixed_snap_ratio >= 0 && config.discretize.fixed_snap_ratio < 0.5))
      s.fail("fixed_snap_ratio: must be in [0, 0.5)");
    config.discretize.speck_area = s.number("speck_area", config.discretize.speck_area);
    if (!(config.discretize.speck_area >= 0)) s.fail("speck_area: must be ≥ 0");
    s.check_unknown();
  }
  {  // [remesh]
    Section s = section("remesh");
    auto& out = config.remesh;
    out.hmin = s.positive("hmin", out.hmin);
    out.hmax = s.positive("hmax", out.hmax);
    out.hausd = s.positive("hausd", out.hausd);
    out.hgrad = s.positive("hgrad", out.hgrad);
    config.remesh_angle_given = s.has("angle");
    out.feature_angle = s.number("angle", out.feature_angle);
    out.max_passes = int(s.integer("max_passes", out.max_passes));
    out.incremental = s.boolean("incremental", out.incremental);
    if (out.hmin > 0 && out.hmax > 0 && out.hmin > out.hmax) s.fail("hmin must not exceed hmax");
    if (out.hgrad < 1) s.fail("hgrad: must be ≥ 1");
    s.check_unknown();
  }
  {  // [output]
    Section s = section("output");
    auto& out = config.output;
    out.vtu_every = int(s.integer("vtu_every", out.vtu_every));
    out.png_every = int(s.integer("png_every", out.png_every));
    if (out.vtu_every < 0 || out.png_every < 0) s.fail("vtu_every, png_every: must be ≥ 0 (0: never)");
    out.field = s.string("field", out.field);
    out.view = s.choice("view", {"iso", "top", "front"}, out.view);
    if (auto size = s.numbers("size", 2); !size.empty()) {
      if (size[0] < 16 || size[1] < 16 || size[0] > 8192 || size[1] > 8192) s.fail("size: each in [16, 8192] pixels");
      out.width = int(size[0]), out.height = int(size[1]);
    }
    s.check_unknown();
  }
  return config;
}

CaseConfig read_case(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  toml::table table;
  try {
    table = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw file_error(file, long(e.source().begin.line), std::string(e.description()));
  }
  for (const auto& o : overrides) apply_override(table, o);
  try {
    CaseConfig config = parse_case(table, file.parent_path());
    config.file = file;
    // Moved, not copied: toml++ copies drop the source file of each value, which
    // Parameters::path needs to resolve a model's file names against the case file.
    config.model_parameters = std::move(*table["model"].as_table());
    config.model_parameters.erase("name");
    return config;
  } catch (const InputError& e) {
    throw file_error(file, e.what());
  }
}

SurfaceMesh make_case_surface(const CaseConfig& config) {
  const auto& s = config.surface;
  switch (s.kind) {
    case SurfaceSpec::Kind::File: {
      SurfaceMesh mesh = read_mesh(s.file);
      return mesh;
    }
    case SurfaceSpec::Kind::Sphere:
      return make_sphere(s.sphere);
    case SurfaceSpec::Kind::Terrain:
      return s.dem.empty() ? make_terrain(s.terrain) : make_terrain_from_grid(read_dem(s.dem), s.terrain.h);
    case SurfaceSpec::Kind::Plane:
      return make_plane(s.plane_size, s.plane_h);
  }
  return {};
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
  // A landscape has no sharp features: on steep terrain many lattice edges exceed the 45° dihedral
  // angle, and ridges detected there froze the remesher (minimum quality 0.06 instead of 0.6 on
  // the fire cases). Feature detection stays off for terrains unless [remesh] angle is given.
  if (config.surface.kind == SurfaceSpec::Kind::Terrain && !config.remesh_angle_given) options.remesh.feature_angle = 0;
  options.remesh.reference = make_case_reference(config, mesh);
  if (config.region.kind == RegionSpec::Kind::Refs) {
    label_from_refs(config, mesh);
    remesh(mesh, options.remesh);
  } else {
    mesh_initial_region(mesh, initial_level_set(config, mesh), config.discretize, options.remesh);
  }
  setup.h = config.remesh.hmax > 0 ? config.remesh.hmax : mean_edge_length(mesh);
  options.dt = config.time.dt > 0 ? config.time.dt : config.time.cfl * setup.h;
  options.final_time = config.time.final_time;
  options.max_cfl = config.time.max_cfl;
  options.cfl_length = setup.h;
  options.max_iterations = config.time.iterations;
  options.distance = config.distance;
  options.advection = config.advection;
  options.discretize = config.discretize;
  options.terrain = config.surface.kind == SurfaceSpec::Kind::Terrain;
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
