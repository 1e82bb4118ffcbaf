// The Balbi wildfire model as a bodyfit plugin (paper §4.3): the burnt region G(t) grows with the
// normal speed R (rate of spread, formula 4.8) computed at every vertex from the local slope, the
// wind and the orientation of the front (extended conormal n_Σ of the context).
#include "balbi.hpp"
#include "barriers.hpp"
#include "fire_maps.hpp"
#include "rothermel_spread.hpp"
#include "wind.hpp"

#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/app/coordinate_system.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/app/map.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/app/plan_geometry.hpp>
#include <bodyfit/app/raster_io.hpp>
#include <bodyfit/app/vector_io.hpp>
#include <bodyfit/velocity_model.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

namespace bodyfit::fire {
namespace {

constexpr double kDegree = M_PI / 180.0;

/// The burnt region of one state seen from above (a feature of the perimeter layer).
struct Perimeter {
  int iteration = 0;
  double time = 0;
  double surface_area = 0;  ///< |G| on the terrain, m²
  std::vector<PlanPolygon> polygons;
};

// Perimeters in a checkpoint: per perimeter (iteration, polygon count), per polygon its ring
// count, per ring its point count, then every point's x and y.
void save_perimeters(const std::vector<Perimeter>& perimeters, ModelState& state) {
  std::vector<std::int64_t> shape;
  std::vector<double> numbers;
  for (const auto& p : perimeters) {
    shape.push_back(p.iteration);
    shape.push_back(std::int64_t(p.polygons.size()));
    numbers.push_back(p.time);
    numbers.push_back(p.surface_area);
    for (const auto& polygon : p.polygons) {
      shape.push_back(std::int64_t(polygon.rings.size()));
      for (const auto& ring : polygon.rings) {
        shape.push_back(std::int64_t(ring.size()));
        for (const auto& point : ring) numbers.insert(numbers.end(), point.begin(), point.end());
      }
    }
  }
  state.set("perimeters.shape", std::move(shape));
  state.set("perimeters.numbers", std::move(numbers));
}

std::vector<Perimeter> load_perimeters(const ModelState& state) {
  std::vector<Perimeter> perimeters;
  if (!state.has("perimeters.shape")) return perimeters;
  const auto& shape = state.integers("perimeters.shape");
  const auto& numbers = state.numbers("perimeters.numbers");
  std::size_t s = 0, n = 0;
  auto count = [&] {
    if (s >= shape.size() || shape[s] < 0) throw InputError("fire model state: the perimeters are inconsistent");
    return std::size_t(shape[s++]);
  };
  auto number = [&] {
    if (n >= numbers.size()) throw InputError("fire model state: the perimeters are inconsistent");
    return numbers[n++];
  };
  while (s < shape.size()) {
    Perimeter p;
    p.iteration = int(count());
    p.polygons.resize(count());
    p.time = number();
    p.surface_area = number();
    for (auto& polygon : p.polygons) {
      polygon.rings.resize(count());
      for (auto& ring : polygon.rings) {
        ring.resize(count());
        for (auto& point : ring) point = {number(), number()};
      }
    }
    perimeters.push_back(std::move(p));
  }
  return perimeters;
}

class FireModel final : public VelocityModel {
 public:
  std::string_view name() const override { return "fire"; }
  std::string_view version() const override { return "1.0"; }
  std::string_view description() const override {
    return "wildfire spread on a terrain: Balbi et al. (2009) rate of spread from slope, wind and front "
           "orientation (paper §4.3), or Rothermel (1972) with standard fuel models, moistures and the fire "
           "ellipse; SI units: metres, seconds";
  }

  std::vector<ParameterDecl> parameters() const override {
    std::vector<ParameterDecl> declared = {
        ParameterDecl::choice("spread", {"balbi", "rothermel"},
                              "the rate of spread: balbi (the paper's, from the preset or R0, A, u0, v0) or rothermel "
                              "(fuel models of a fuel table, [model.moisture], the elliptical fire shape)")
            .fallback("balbi"),
        ParameterDecl::choice("preset", {"balbi2009", "paper_table1"},
                              "fuel parameter set: balbi2009 (R0 0.398 m/s, A 1.873) or paper_table1 (R0 2.7 m/s, A 1.25)")
            .fallback("balbi2009"),
        ParameterDecl::number("R0", "m/s", "rate of spread without slope and wind").computed("the preset's").positive(),
        ParameterDecl::number("A", "1", "radiant / ignition energy ratio").computed("the preset's").positive(),
        ParameterDecl::number("u0", "m/s", "combustion gas velocity").fallback(39.8).positive(),
        ParameterDecl::number("v0", "m/s", "flame-base velocity").computed("12·R0").positive(),
        ParameterDecl::number("max_tilt_deg", "degrees", "cap on the tilt angle γ (< 90)")
            .fallback(80.0)
            .within({.min = 0, .max = 90, .min_exclusive = true, .max_exclusive = true}),
        ParameterDecl::choice("front_velocity", {"huygens", "normal"},
                              "huygens: V = R n_Σ + (dR/dθ) t, along the front's characteristics (Huygens' "
                              "principle); normal: V = R n_Σ as in the paper. The same front as the steps shrink; "
                              "huygens is closer at a given step")
            .fallback("huygens"),
        ParameterDecl::boolean("landscape_statistics",
                               "R at every vertex of the landscape (the rate_of_spread field, the metrics "
                               "ros_all_mean and ros_all_max), through the front normal extended by d on the whole "
                               "surface; false: R where the front can go within the step (d's band), the run's "
                               "costs following the front")
            .fallback(false),
        ParameterDecl::choice("slope", {"surface", "mesh"},
                              "surface: the slope from the input surface's smooth normal, one field whatever the "
                              "mesh; mesh: from the current mesh's vertex normals, which change with every remesh")
            .fallback("surface"),
        ParameterDecl::path("fuel.map", "raster of fuel codes: balbi: k ≥ 1 = fuel.presets[k−1]; rothermel: the "
                                        "fuel table's codes; 0, NODATA and fuel.non_burnable do not burn"),
        ParameterDecl::choice("fuel.table", builtin_fuel_tables(),
                              "rothermel: the fuel models, Scott & Burgan (2005) 40 or Anderson (1982) 13")
            .fallback("scott_burgan40"),
        ParameterDecl::path("fuel.table_file", "rothermel: a fuel table of your own (CSV with units in the header, "
                                               "docs/reference/fire_model.md \"Fuel tables\"), instead of fuel.table"),
        ParameterDecl::string("fuel.model", "rothermel: the fuel model everywhere, by code or name (\"GR2\", \"102\"), "
                                            "without a fuel.map"),
        ParameterDecl::strings("fuel.presets", "parameter sets of the codes of fuel.map (default: [preset])"),
        ParameterDecl::numbers("fuel.non_burnable", 0, "", "more codes of fuel.map that do not burn (water, rock, e.g. "
                                                            "[98, 99])")
            .fallback(std::vector<double>{}),
        ParameterDecl::number("arrival.cell_size", "m", "cell size of the arrival-time grid")
            .computed("the mean edge length")
            .at_least(0),
        ParameterDecl::path("arrival.like", "a raster (e.g. the DEM) whose cells the arrival-time grid uses"),
        ParameterDecl::string("perimeters.file", "the burnt region's outline at every perimeters.every-th state and "
                                                 "the last (.gpkg or .geojson; \"\": none)")
            .fallback(config::have_gdal ? "perimeters.gpkg" : ""),
        ParameterDecl::integer("perimeters.every", "iterations", "a perimeter every this many iterations")
            .fallback(1)
            .at_least(1),
        ParameterDecl::path("barriers.file", "roads, rivers, fuel breaks, lakes: lines and polygons of a vector layer "
                                             "(GeoJSON, Shapefile, GeoPackage) where R = 0 within max(width/2, 2 × the "
                                             "longest edge)")
            .require(),
        ParameterDecl::string("barriers.layer", "the layer of barriers.file").computed("the first"),
        ParameterDecl::number("barriers.width", "m", "width of the barriers (narrower than the mesh: they act with its "
                                                     "width)")
            .fallback(0.0)
            .at_least(0),
    };
    declared.push_back(ParameterDecl::number("canopy.base_height", "m", "rothermel: canopy base height (crown fire)")
                           .at_least(0));
    declared.push_back(ParameterDecl::path("canopy.base_height_map", "rothermel: canopy base height per cell, m"));
    declared.push_back(ParameterDecl::number("canopy.bulk_density", "kg/m³", "rothermel: canopy bulk density (crown "
                                                                            "fire; 0: no canopy)")
                           .at_least(0));
    declared.push_back(ParameterDecl::path("canopy.bulk_density_map", "rothermel: canopy bulk density per cell, kg/m³"));
    declared.push_back(ParameterDecl::number("canopy.cover", "%", "rothermel: canopy cover (with canopy.height: the "
                                                                 "sheltered wind adjustment factor)")
                           .within({.min = 0, .max = 100}));
    declared.push_back(ParameterDecl::path("canopy.cover_map", "rothermel: canopy cover per cell, %"));
    declared.push_back(ParameterDecl::number("canopy.height", "m", "rothermel: canopy (stand) height").at_least(0));
    declared.push_back(ParameterDecl::path("canopy.height_map", "rothermel: canopy height per cell, m"));
    declared.push_back(ParameterDecl::path("landscape", "rothermel: a FARSITE landscape (.lcp): its fuel band is the "
                                                        "fuel map (codes of fuel.table), its canopy bands the canopy"));
    declared.push_back(ParameterDecl::number("canopy.foliar_moisture", "%", "rothermel: foliar moisture content")
                           .fallback(100.0)
                           .positive());
    declared.push_back(ParameterDecl::boolean("limit_effective_wind", "rothermel: cap the effective wind at 0.9 × the "
                                                                     "reaction intensity (Rothermel 1972), as BehavePlus")
                           .fallback(true));
    for (ParameterDecl& d : wind_parameters()) declared.push_back(std::move(d));
    for (ParameterDecl& d : moisture_parameters()) declared.push_back(std::move(d));
    return declared;
  }

  std::vector<OutputDecl> outputs() const override {
    return {
        OutputDecl::vertex_field("rate_of_spread", "m/s", "R at the vertices near the front (0 beyond; with "
                                                          "landscape_statistics, everywhere through the extended front normal)"),
        OutputDecl::vertex_field("arrival_time", "s", "the arrival-time grid sampled at the vertices (terrains)"),
        OutputDecl::metric("ros_min", "m/s", "smallest R on the front"),
        OutputDecl::metric("ros_mean", "m/s", "mean R on the front"),
        OutputDecl::metric("ros_max", "m/s", "largest R on the front"),
        OutputDecl::metric("ros_all_mean", "m/s", "with landscape_statistics: mean R over the whole surface"),
        OutputDecl::metric("ros_all_max", "m/s", "with landscape_statistics: largest R over the whole surface"),
        OutputDecl::grid("arrival_time", "s", "the time the front reached each cell (terrains)")
            .combine(Combine::share("burn_probability", "burn probability over {members} members"))
            .combine(Combine::mean("arrival_mean", "s", "mean arrival time over the members that reached the cell"))
            .combine(Combine::percentiles("arrival_p", "s", "arrival time, percentile {percentile} over the members "
                                                            "that reached the cell")),
        OutputDecl::grid("rate_of_spread", "m/s", "the rate of spread at which each cell burnt (terrains)")
            .combine(Combine::mean("ros_mean", "m/s", "rate of spread at which the cell burnt, mean over the members "
                                                      "that burnt it (cells burning at the start have none)")),
        OutputDecl::grid("fireline_intensity", "kW/m",
                         "rothermel: Byram's fireline intensity at which each cell burnt (heat per unit area × rate)"),
        OutputDecl::grid("flame_length", "m", "rothermel: Byram's flame length at which each cell burnt"),
        OutputDecl::grid("heat_per_unit_area", "kJ/m²", "rothermel: the heat each burnt cell released per unit area"),
        OutputDecl::grid("fire_type", "1", "rothermel with [model.canopy]: 1 surface, 2 passive crown, 3 active "
                                           "crown fire, where each cell burnt"),
        OutputDecl::value("burnt_area", "m²", "|G| at the end: the area burnt, on the surface"),
        OutputDecl::file("perimeters.gpkg", "the burnt region's outline (perimeters.file)"),
        OutputDecl::file("perimeters.geojson", "the same as GeoJSON (perimeters.file)"),
        OutputDecl::file("fire_map.png", "the run's map: hillshade, burnt area, isochrones"),
    };
  }

  void set_surface(const SurfaceSource& source) override { surface_ = source; }

  void configure(Parameters& p) override {
    rothermel_ = p.choice("spread") == "rothermel";
    arrival_.record({});
    huygens_ = p.choice("front_velocity") == "huygens";
    surface_slope_ = p.choice("slope") == "surface";
    landscape_statistics_ = p.boolean("landscape_statistics");

    wind_height_ = WindHeight::midflame;
    if (p.has("wind")) {
      Parameters& w = p.section("wind");
      wind_ = read_wind_table(w, [&](const std::filesystem::path& file) {
        return read_model_raster(file, Resampling::bilinear);
      });
      parse_wind_height(w.choice("height"), wind_height_);
      if (!rothermel_ && wind_height_ != WindHeight::midflame)
        w.fail("height", "spread = \"balbi\" takes the wind at the flame (midflame): its fuel has no bed depth "
                         "to bring another height down to it");
    }
    fuel_map_ = HeightGrid();
    fuel_file_.clear();
    non_burnable_.clear();
    if (rothermel_) {
      rothermel_spread_.configure(p, [&](const std::filesystem::path& file, Resampling resampling,
                                         std::optional<LandscapeBand> band) {
        return read_model_raster(file, resampling, band);
      });
      arrival_.record(rothermel_spread_.recorded_names());
    } else {
      configure_balbi(p);
    }
    if (p.has("fuel")) {
      Parameters& f = p.section("fuel");
      for (double code : f.numbers("non_burnable")) {
        if (code != std::round(code) || std::abs(code) > 1e15)
          f.fail("non_burnable", fmt::format("{} is not an integer fuel code", code));
        non_burnable_.push_back(std::llround(code));
      }
      fuel_file_ = f.path("map");
      if (!fuel_file_.empty()) {
        fuel_map_ = read_model_raster(fuel_file_, Resampling::nearest);
        check_fuel_codes();
      }
    }
    if (rothermel_ && !rothermel_spread_.landscape().empty()) {  // a FARSITE landscape's fuel band
      fuel_file_ = rothermel_spread_.landscape();
      fuel_map_ = read_model_raster(fuel_file_, Resampling::nearest, LandscapeBand::fuel);
      check_fuel_codes();
    }
    if (p.has("arrival")) {
      Parameters& a = p.section("arrival");
      arrival_cell_ = a.number("cell_size", 0);
      const std::filesystem::path like = a.path("like");
      arrival_like_file_ = like;
      if (!like.empty()) arrival_like_ = read_model_raster(like, Resampling::bilinear);
    }
    if (p.has("perimeters")) {
      Parameters& q = p.section("perimeters");
      perimeter_file_ = q.string("file");
      perimeter_every_ = int(q.integer("every"));
    }
    if (p.has("barriers")) {
      Parameters& b = p.section("barriers");
      BarrierOptions options;
      options.file = b.path("file");
      options.layer = b.string("layer", "");
      options.width = b.number("width");
      if (options.file.empty()) b.fail("file", "expected a vector layer of barriers");
      barriers_ = Barriers::read(options, surface_);
    } else {
      barriers_ = Barriers();
    }
    // The rasters of one case share one coordinate system, the surface's when it has one (each
    // raster was checked against it as it was read), which the outputs then carry.
    std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters;
    if (fuel_map_.cols > 0) rasters.emplace_back(&fuel_map_, fuel_file_);
    for (const auto& raster : wind_.rasters()) rasters.push_back(raster);
    if (arrival_like_.cols > 0) rasters.emplace_back(&arrival_like_, arrival_like_file_);
    if (rothermel_)
      for (const auto& raster : rothermel_spread_.rasters()) rasters.push_back(raster);
    rasters_ = rasters;
    crs_ = surface_.crs;
    const HeightGrid* first = nullptr;
    std::filesystem::path first_file;
    for (const auto& [grid, file] : rasters) {
      if (grid->crs.empty()) continue;
      if (first) require_same_crs(*first, first_file, *grid, file);
      else {
        first = grid;
        first_file = file;
        if (crs_.empty()) crs_ = grid->crs;
      }
    }
  }

  /// Every raster of the model covers the terrain: outside its extent a point takes the nearest edge
  /// cell, so a map of another place (a fuel map 200 km off) would be read without a word. None of
  /// the terrain covered is an error; less than 90 % a warning.
  void check_raster_extents(const BoundingBox& terrain) {
    extents_checked_ = true;
    const double dx = terrain.max[0] - terrain.min[0], dy = terrain.max[1] - terrain.min[1];
    if (!(dx > 0 && dy > 0)) return;
    for (const auto& [grid, file] : rasters_) {
      const double x0 = grid->x_origin, x1 = x0 + double(grid->cols) * grid->cell_size;
      const double y0 = grid->y_origin, y1 = y0 + double(grid->rows) * grid->cell_size;
      const double wx = std::min(x1, terrain.max[0]) - std::max(x0, terrain.min[0]);
      const double wy = std::min(y1, terrain.max[1]) - std::max(y0, terrain.min[1]);
      const double covered = wx > 0 && wy > 0 ? wx * wy / (dx * dy) : 0.0;
      const std::string where = fmt::format("{}: its extent x {:.1f}..{:.1f}, y {:.1f}..{:.1f} and the terrain's x "
                                            "{:.1f}..{:.1f}, y {:.1f}..{:.1f}",
                                            file.string(), x0, x1, y0, y1, terrain.min[0], terrain.max[0],
                                            terrain.min[1], terrain.max[1]);
      if (covered == 0)
        throw InputError(fmt::format("{} do not overlap: the raster is of another place (or in other coordinates)",
                                     where));
      if (covered < 0.9)
        spdlog::warn("{}: it covers {:.0f} % of the terrain; beyond it, points take its nearest edge cell", where,
                     100 * covered);
    }
  }

  // R needs d near the front only; the landscape's statistics (R over every vertex, each with the
  // extended n_Σ) need it everywhere.
  ModelNeeds needs() const override { return {.whole_surface_distance = landscape_statistics_}; }

  VelocityField compute(const StepContext& context) override {
    const SurfaceMesh& mesh = context.mesh();
    const VectorField& conormal = context.conormal();
    // The terrain's orientation: S's own smooth normal, the same at a point whatever mesh samples it.
    // The remeshed T^n's vertex normals average other faces at every step, and the front picked up
    // that noise in R (docs/reference/fire_model.md, "Slope from the surface").
    const VectorField& normals = surface_slope_ ? context.surface_normals() : context.vertex_normals();
    if (!extents_checked_) check_raster_extents(bounding_box(mesh));
    if (!wind_.has_center) {
      BoundingBox box = bounding_box(mesh);
      wind_.center = 0.5 * (box.min + box.max);
      wind_.has_center = true;
    }
    // A wind series is a function of time: V at the time of this (sub-)step (docs/reference/fire_model.md, "Wind in time").
    wind_.set_clock(context.clock_start());
    const double time = context.time();
    if (context.is_height_field() && !arrival_.initialised()) arrival_.initialise(mesh, arrival_cell_, arrival_like_, context.mesh_size());

    ScalarField speed(mesh.n_vertices(), 0.0);
    const std::span<const int> active = context.active_vertices();
    // Where R is needed: a sub-step's active vertices, d's band in a banded state (empty: all).
    const std::span<const int> band = context.band_vertices();
    if (!barriers_.empty()) {
      // The band's sub-steps work on the mesh of the state's own compute (T^n): its longest edge.
      if (active.empty() || !(barrier_reach_ > 0)) barrier_reach_ = barrier_reach(barriers_, longest_plan_edge(mesh));
      mark_barrier_vertices(mesh, barriers_, barrier_reach_, band, stopped_);
    }
    if (rothermel_)
      rothermel_spread_.update(mesh, normals, band, time, context.clock_start(), wind_, wind_height_,
                               [&](double x, double y) { return fuel_at(x, y); });
    auto rate_in = [&](int v, const Vec3& n_sigma) {
      if (!barriers_.empty() && stopped_[std::size_t(v)]) return 0.0;  // a barrier: the front stops here
      if (rothermel_) return rothermel_spread_.rate(v, n_sigma);
      const Vec3& x = mesh.point(VertexHandle(v));
      const int index = fuel_at(x[0], x[1]);
      if (index < 0) return 0.0;  // not burnable: the front stops here
      const BalbiParameters* fuel = &balbi_fuel(index);
      if (n_sigma.sqrnorm() == 0) return fuel->R0;
      const Vec3& normal = normals[v];
      // ∇_S s · n_Σ = e3 · n_Σ because n_Σ is tangent (∇_S s = e3 − (e3·N)N).
      double slope_term = n_sigma[2];
      double wind_term = OpenMesh::dot(wind_.at(x, time), n_sigma);
      double tan_gamma = tan_tilt(slope_term, std::abs(normal[2]), wind_term, *fuel);
      return rate_of_spread(std::atan(tan_gamma), *fuel);
    };
    // n_Σ in the tangent plane of the normal the slope is read from (∇_S s · n_Σ = e3 · n_Σ holds there).
    auto front_normal = [&](int v) {
      const Vec3& n = conormal[v];
      if (!surface_slope_ || n.sqrnorm() == 0) return n;
      const Vec3 tangent = n - OpenMesh::dot(n, normals[v]) * normals[v];
      const double length = tangent.norm();
      return length > 1e-12 ? tangent / length : n;
    };
    auto rate_at = [&](int v) { return rate_in(v, front_normal(v)); };
    // Huygens' principle: the front's points move along the characteristics of R(n)|∇φ|, at
    // V = R n + (dR/dθ) t with t the tangent of the front (n turned by +90° about the normal of S).
    // V·∇φ = R|∇φ| as for V = R n, so the front moves the same at any instant; but R n turns with
    // n along a step while this V does not, and a step traced with it no longer runs ahead of the
    // Wulff shape on the flanks of a head (docs/reference/fire_model.md, "Huygens' velocity"). dR/dθ by a central
    // difference over ±1e-3 rad: the same for any R(n), wind and fuel included.
    auto huygens_at = [&](int v, double rate) {
      const Vec3 n = front_normal(v);
      if (n.sqrnorm() == 0) return Vec3(0, 0, 0);
      Vec3 t = OpenMesh::cross(normals[v], n);
      const double length = t.norm();
      if (!(length > 0)) return rate * n;
      t /= length;
      constexpr double turn = 1e-3;
      const double c = std::cos(turn), s = std::sin(turn);
      const double slope = (rate_in(v, c * n + s * t) - rate_in(v, c * n - s * t)) / (2 * turn);
      return rate * n + slope * t;
    };
    // A sub-step in a narrow band needs R at the band's vertices only, and no metrics or fields.
    // (Each vertex on its own: in parallel.)
    if (!active.empty()) {
      if (rates_.size() != mesh.n_vertices()) rates_.assign(mesh.n_vertices(), 0.0);
      VectorField velocity(huygens_ ? mesh.n_vertices() : 0, Vec3(0, 0, 0));
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active.size(), 128), [&](const auto& range) {
        for (std::size_t k = range.begin(); k < range.end(); ++k) {
          const int v = active[k];
          speed[v] = rates_[std::size_t(v)] = rate_at(v);
          if (huygens_) velocity[v] = huygens_at(v, speed[v]);
        }
      });
      if (huygens_) return VelocityField::tangential(std::move(velocity));
      return VelocityField::normal(std::move(speed));
    }
    auto over_band = [&](auto&& visit) {
      const std::size_t n = band.empty() ? mesh.n_vertices() : band.size();
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 128), [&](const auto& range) {
        for (std::size_t k = range.begin(); k < range.end(); ++k)
          if (!band.empty()) visit(band[k]);
          else if (!mesh.status(VertexHandle(int(k))).deleted()) visit(int(k));
      });
    };
    over_band([&](int v) { speed[v] = rate_at(v); });
    rates_ = speed;  // the state's own compute: the rates the arrival raster records in its steps
    clock_start_ = context.clock_start();
    if (context.is_height_field()) record_perimeter(context);

    VelocityField field = VelocityField::normal(speed);
    if (huygens_) {
      field.kind = VelocityField::Kind::Tangential;
      field.vector.assign(mesh.n_vertices(), Vec3(0, 0, 0));
      over_band([&](int v) { field.vector[v] = huygens_at(v, speed[v]); });
    }
    // Rate of spread on the front: vertices of interface edges.
    double lo = std::numeric_limits<double>::infinity(), hi = 0, sum = 0;
    std::size_t count = 0;
    std::vector<char> on_front(mesh.n_vertices(), 0);
    for (auto e : mesh.edges())
      if (mesh.interface(e))
        for (int i = 0; i < 2; ++i) on_front[mesh.to_vertex_handle(mesh.halfedge_handle(e, i)).idx()] = 1;
    for (auto v : mesh.vertices())
      if (on_front[v.idx()]) {
        lo = std::min(lo, speed[v.idx()]);
        hi = std::max(hi, speed[v.idx()]);
        sum += speed[v.idx()];
        ++count;
      }
    field.metrics = {{"ros_min", count ? lo : 0.0}, {"ros_mean", count ? sum / double(count) : 0.0}, {"ros_max", hi}};
    if (landscape_statistics_) {
      // Over the whole landscape too (R is defined everywhere through the extended n_Σ): the speed
      // field a figure of S coloured by R shows.
      double all_sum = 0, all_max = 0;
      for (double r : speed) all_sum += r, all_max = std::max(all_max, r);
      field.metrics.emplace_back("ros_all_mean", speed.empty() ? 0.0 : all_sum / double(speed.size()));
      field.metrics.emplace_back("ros_all_max", all_max);
    }
    field.point_fields.emplace_back("rate_of_spread", speed);
    if (arrival_.initialised()) field.point_fields.emplace_back("arrival_time", arrival_.sample_at_vertices(mesh));
    return field;
  }

  void end_step(const StepOutcome& outcome) override {
    // dt = 0: a region joined G (a late ignition) on the accepted state, whose rates are not
    // rates_ (those of the state before): its cells arrive at that time with no rate of spread.
    if (arrival_.initialised()) {
      const bool current = outcome.dt > 0 && rates_.size() == outcome.mesh.n_vertices();
      std::vector<const ScalarField*> recorded;
      if (rothermel_ && current) recorded = rothermel_spread_.recorded(outcome.mesh.n_vertices());
      arrival_.update(outcome.mesh, outcome.distance, outcome.phi_next, outcome.time, outcome.dt, outcome.changed,
                      current ? &rates_ : nullptr, recorded);
    }
  }

  // What a resumed run needs to continue exactly: the arrival times so far and the rotating wind's
  // centre (taken from the first mesh's bounding box when the case does not give it).
  void save_state(ModelState& state) const override {
    state.version = 1;
    arrival_.save(state);
    save_perimeters(perimeters_, state);
    if (wind_.has_center) state.set("wind.center", std::vector<double>{wind_.center[0], wind_.center[1], wind_.center[2]});
  }

  void load_state(const ModelState& state) override {
    if (state.version != 1)
      throw InputError(fmt::format("fire model state version {} (this plugin reads version 1)", state.version));
    arrival_.load(state);
    perimeters_ = load_perimeters(state);
    if (state.has("wind.center")) {
      const auto& c = state.numbers("wind.center");
      if (c.size() != 3) throw InputError("fire model state: wind.center needs 3 numbers");
      wind_.center = Vec3(c[0], c[1], c[2]);
      wind_.has_center = true;
    }
  }

  void finish(const StepContext& final_state, ModelOutputs& outputs) override {
    const std::filesystem::path& output_dir = final_state.output_dir();
    outputs.value("burnt_area", region_area(final_state.mesh(), kInside));
    if (arrival_.initialised()) {
      const std::string since = clock_start_ ? "after " + format_iso8601(*clock_start_) : "after the start (t = 0)";
      std::vector<std::pair<std::string, std::string>> items;
      if (clock_start_) items.emplace_back("START_TIME", format_iso8601(*clock_start_));
      outputs.grid("arrival_time", grid_field(arrival_.grid(), "fire arrival time, seconds " + since, items, crs_));
      outputs.grid("rate_of_spread",
                   grid_field(arrival_.rate_grid(),
                              fmt::format("rate of spread ({}) at which the cell burnt, m/s (NODATA: not reached, or "
                                          "burning at the start)",
                                          rothermel_ ? "Rothermel" : "Balbi"),
                              items, crs_));
      if (rothermel_) rothermel_spread_.write_grids(outputs, arrival_, items, crs_);
    }
    if (output_dir.empty()) return;
    write_perimeters(output_dir);
    // The run's map (docs/reference/fire_model.md, "Maps"): the final state's mesh, which final.mesh was just written
    // from (reading it back would give the same mesh), and the layers from the files just written. A map that
    // cannot be drawn (no Cairo) costs the run nothing: its results are all written.
    // Only after `bodyfit run`, which writes final.mesh first; not when a program calls evolve().
    if (!arrival_.initialised() || !config::have_cairo || !std::filesystem::exists(output_dir / "final.mesh")) return;
    try {
      const MapLayers layers = load_map_layers(output_dir);
      const MapOptions options{.title = "Fire map: burnt area and arrival time"};
      if (!has_deleted_elements(final_state.mesh())) {
        draw_fire_map(output_dir / "fire_map.png", final_state.mesh(), layers, options);
      } else {  // as final.mesh holds it: compacted
        SurfaceMesh mesh = final_state.mesh();
        collect_garbage(mesh);
        draw_fire_map(output_dir / "fire_map.png", mesh, layers, options);
      }
    } catch (const std::exception& e) {
      spdlog::warn("fire_map.png not drawn: {}", e.what());
    }
  }

  std::vector<std::string> output_files() const override {
    std::vector<std::string> files = declared_output_files(outputs());
    if (!perimeter_file_.empty() && std::find(files.begin(), files.end(), perimeter_file_) == files.end())
      files.push_back(perimeter_file_);
    return files;
  }

 private:
  // Balbi's parameters: the preset's, or per fuel class of the fuel map; Rothermel's keys refused.
  void configure_balbi(Parameters& p) {
    p.forbid({"moisture", "limit_effective_wind", "canopy", "landscape"},
             "to spread = \"balbi\" (Rothermel's: set spread = \"rothermel\")");
    const std::string preset_name = p.choice("preset");
    base_ = preset(preset_name);
    base_.u0 = p.number("u0");
    base_.max_tilt = p.number("max_tilt_deg") * kDegree;
    fuels_.clear();
    if (!p.has("fuel")) {
      base_.R0 = p.number("R0", base_.R0);
      base_.A = p.number("A", base_.A);
      base_.v0 = p.number("v0", 12 * base_.R0);
      return;
    }
    // Each fuel class is a preset: R0, A and v0 come from it, not from [model].
    for (const char* key : {"R0", "A", "v0"})
      p.not_used(key, fmt::format("{} is set per fuel class by [model.fuel] presets; give it in the fuel table", key));
    Parameters& f = p.section("fuel");
    f.forbid({"table", "table_file", "model"}, "to spread = \"balbi\" (fuel tables are Rothermel's: fuel.presets "
                                               "name Balbi's parameter sets)");
    std::vector<std::string> names = f.strings("presets");
    if (names.empty()) names.push_back(preset_name);
    for (auto& n : names) {
      try {
        BalbiParameters q = preset(n);
        q.max_tilt = base_.max_tilt;
        q.u0 = base_.u0;
        fuels_.push_back(q);
      } catch (const std::invalid_argument& e) {
        f.fail("presets", e.what());
      }
    }
  }

  // The state's outline, once per iteration (sub-steps and retried steps compute on the same
  // state); kept when it is a perimeters.every-th state, and always as the latest (the final state
  // is the last one computed: finish() adds it).
  void record_perimeter(const StepContext& context) {
    if (perimeter_file_.empty() || context.output_dir().empty()) return;
    const int iteration = context.iteration();
    if (!perimeters_.empty() && perimeters_.back().iteration >= iteration) return;
    if (latest_ && latest_->iteration == iteration) return;
    Perimeter p{.iteration = iteration,
                .time = context.time(),
                .surface_area = region_area(context.mesh(), kInside),
                .polygons = region_outline(context.mesh(), kInside)};
    if (iteration % perimeter_every_ == 0) {
      perimeters_.push_back(std::move(p));
      latest_.reset();
      write_perimeters(context.output_dir());
    } else {
      latest_ = std::move(p);
    }
  }

  // The perimeter layer as it stands (rewritten whole, atomically: a killed run leaves the
  // previous one).
  void write_perimeters(const std::filesystem::path& output_dir) const {
    if (perimeter_file_.empty() || output_dir.empty() || (perimeters_.empty() && !latest_)) return;
    VectorLayer layer;
    layer.name = "perimeters";
    layer.crs = crs_;
    auto add = [&](const Perimeter& p) {
      VectorFeature f;
      f.geometry.polygons = p.polygons;
      double area = 0, length = 0;
      for (const auto& polygon : p.polygons) area += polygon_area(polygon), length += polygon_perimeter(polygon);
      f.attributes = {{"iteration", std::int64_t(p.iteration)}, {"time", p.time}};
      if (clock_start_) f.attributes.emplace_back("datetime", format_iso8601(*clock_start_ + p.time));
      f.attributes.emplace_back("area", area);
      f.attributes.emplace_back("perimeter", length);
      f.attributes.emplace_back("surface_area", p.surface_area);
      layer.features.push_back(std::move(f));
    };
    for (const auto& p : perimeters_) add(p);
    if (latest_) add(*latest_);
    // The GeoPackage's own stamp (last_change): the clock time of its latest perimeter, or the
    // epoch without [time] start; never the time of writing, so a resumed run writes the same bytes.
    if (clock_start_) layer.timestamp = *clock_start_ + (latest_ ? latest_->time : perimeters_.back().time);
    write_polygon_layer(output_dir / perimeter_file_, layer);
  }

  // A raster of the model in the surface's coordinate system: one in the DEM's own system when the
  // case reprojected the DEM is warped like it (`resampling`: nearest for codes), one in another
  // system is an InputError naming both files, one without a system is taken as the surface's.
  HeightGrid read_model_raster(const std::filesystem::path& file, Resampling resampling,
                               std::optional<LandscapeBand> band = std::nullopt) const {
    DemReadOptions options;
    if (!surface_.reprojected_from.empty())
      options = {.reproject = Reprojection::utm, .target_crs = surface_.crs, .resampling = resampling};
    HeightGrid grid = band ? read_landscape_band(file, *band, options) : read_raster(file, options);
    if (grid.crs.empty() && !surface_.crs.empty())
      spdlog::warn("{}: no coordinate system: its cells are taken as in the surface's ({})", file.string(),
                   crs_label(surface_.crs, surface_.file));
    require_crs(grid.crs, file, surface_.crs, surface_.file);
    return grid;
  }

  bool non_burnable(long long code) const {
    return code == 0 || std::find(non_burnable_.begin(), non_burnable_.end(), code) != non_burnable_.end();
  }

  // Every cell of the fuel map is NODATA, a non-burnable code or a fuel's code (balbi: a preset's
  // number; rothermel: a code of the fuel table): any other value is an error naming its cell.
  void check_fuel_codes() const {
    for (std::size_t row = 0; row < fuel_map_.rows; ++row)
      for (std::size_t col = 0; col < fuel_map_.cols; ++col) {
        if (!fuel_map_.valid(row, col)) continue;
        const double value = fuel_map_.at(row, col);
        const bool integer = value == std::round(value) && std::abs(value) < 1e15;
        if (integer && (non_burnable(std::llround(value)) || fuel_of_code(std::llround(value)) >= 0)) continue;
        const std::string fuels =
            rothermel_ ? fmt::format("a code of the fuel table {}", rothermel_spread_.table().source)
                       : fmt::format("a preset's number (1 to {}: [model.fuel] presets)", fuels_.size());
        throw InputError(fmt::format("{}: the fuel code {} of the cell at row {}, column {} is neither {} nor 0, NODATA "
                                     "({}) or a code of [model.fuel] non_burnable",
                                     fuel_file_.string(), value, row + 1, col + 1, fuels, fuel_map_.nodata));
      }
  }

  // The fuel of a code of the map: an index into fuels_ (balbi) or beds_ (rothermel), −1 for none.
  int fuel_of_code(long long code) const {
    if (rothermel_) return rothermel_spread_.fuel_of_code(code);
    return code >= 1 && std::size_t(code) <= fuels_.size() ? int(code - 1) : -1;
  }

  // The fuel at a point: the uniform one, or the map's code (NODATA, 0 and the non-burnable codes: −1).
  int fuel_at(double x, double y) const {
    if (fuel_map_.cols == 0) return 0;
    const double value = raster_nearest(fuel_map_, x, y);
    if (std::isnan(value) || value == fuel_map_.nodata) return -1;  // no data is no fuel
    const long long code = std::llround(value);
    return non_burnable(code) ? -1 : fuel_of_code(code);
  }
  const BalbiParameters& balbi_fuel(int index) const { return fuels_.empty() ? base_ : fuels_[std::size_t(index)]; }

  SurfaceSource surface_;  ///< what S was built from (set_surface): its CRS is the case's
  Barriers barriers_;
  double barrier_reach_ = 0;   ///< of the state's own compute (barrier_reach)
  std::vector<char> stopped_;  ///< 1 at the vertices a barrier blocks
  bool rothermel_ = false;  ///< spread: Rothermel's ellipse (true) or Balbi's (4.8)
  BalbiParameters base_;
  std::vector<BalbiParameters> fuels_;
  RothermelSpread rothermel_spread_;  ///< spread = "rothermel": fuels, moistures, canopy, the ellipse
  WindHeight wind_height_ = WindHeight::midflame;
  std::vector<long long> non_burnable_;  ///< codes of the fuel map that do not burn, besides 0 and NODATA
  HeightGrid fuel_map_;
  WindField wind_;
  double arrival_cell_ = 0;
  HeightGrid arrival_like_;
  std::string crs_;
  std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters_;  ///< the model's rasters (configure)
  bool extents_checked_ = false;  ///< they cover the terrain (on the first compute)
  std::filesystem::path fuel_file_, arrival_like_file_;  ///< the coordinate system of the model's rasters (WKT; "" when none says), for its outputs
  ArrivalRaster arrival_;
  bool huygens_ = true;  ///< front_velocity: V = R n + (dR/dθ) t (true) or R n (the paper's)
  bool surface_slope_ = true;  ///< slope: from S's smooth normal (true) or T^n's vertex normals
  bool landscape_statistics_ = false;  ///< R on the whole landscape (d on the whole surface)
  ScalarField rates_;  ///< R at the vertices of the current state (the band's updated in sub-steps)
  std::string perimeter_file_ = config::have_gdal ? "perimeters.gpkg" : "";
  int perimeter_every_ = 1;
  std::vector<Perimeter> perimeters_;
  std::optional<Perimeter> latest_;  ///< the latest state's, when not a perimeters.every-th
  std::optional<double> clock_start_;
};

}  // namespace
}  // namespace bodyfit::fire

BODYFIT_PLUGIN(bodyfit::fire::FireModel)
