// The Balbi wildfire model as a bodyfit plugin (paper §4.3): the burnt region G(t) grows with the
// normal speed R (rate of spread, formula 4.8) computed at every vertex from the local slope, the
// wind and the orientation of the front (extended conormal n_Σ of the context).
#include "balbi.hpp"
#include "fire_maps.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace bodyfit::fire {
namespace {

constexpr double kDegree = M_PI / 180.0;

class FireModel final : public VelocityModel {
 public:
  std::string_view name() const override { return "fire"; }
  std::string_view version() const override { return "1.0"; }
  std::string_view description() const override {
    return "Balbi et al. (2009) rate of spread from slope, wind and front orientation (paper §4.3); "
           "SI units: metres, seconds";
  }

  std::vector<ParameterInfo> parameters() const override {
    return {
        {"preset", "\"balbi2009\"", "fuel parameter set: balbi2009 (R0 0.398 m/s, A 1.873) or paper_table1 (R0 2.7 m/s, A 1.25)"},
        {"R0", "(preset)", "rate of spread without slope and wind, m/s"},
        {"A", "(preset)", "radiant / ignition energy ratio, dimensionless"},
        {"u0", "39.8", "combustion gas velocity, m/s"},
        {"v0", "12*R0", "flame-base velocity, m/s"},
        {"max_tilt_deg", "80", "cap on the tilt angle γ, degrees (< 90)"},
        {"wind.type", "\"none\"", "none | uniform | rotating | grid"},
        {"wind.velocity", "[0, 0]", "uniform wind (x, y), m/s"},
        {"wind.speed, wind.direction_deg", "", "uniform wind as speed (m/s) and the direction it blows from (degrees "
                                               "clockwise from north), instead of velocity"},
        {"wind.center", "(domain centre)", "rotating wind centre (x, y), m: U = scale·(y − yc, −(x − xc), 0)"},
        {"wind.scale", "0.001", "rotating wind angular rate, 1/s (m/s of wind per m from the centre)"},
        {"wind.u_file, wind.v_file", "", "gridded wind components, ESRI ASCII grids (m/s)"},
        {"fuel.map", "", "ESRI ASCII grid of fuel codes: 0 = not burnable, k ≥ 1 = fuel.presets[k−1]"},
        {"fuel.presets", "[preset]", "parameter sets of the codes of fuel.map"},
        {"arrival.cell_size", "(mean edge length)", "cell size of the arrival-time raster, m"},
        {"arrival.like", "", "an ESRI ASCII grid (e.g. the DEM) whose raster the arrival times use"},
    };
  }

  void configure(const toml::table& table) override {
    Parameters p(table, "model");
    p.accept("name");
    const std::string preset_name = p.choice("preset", "balbi2009", {"balbi2009", "paper_table1"});
    base_ = preset(preset_name);
    base_.R0 = p.number("R0", base_.R0, {.min = 0, .min_exclusive = true});
    base_.A = p.number("A", base_.A, {.min = 0, .min_exclusive = true});
    base_.u0 = p.number("u0", base_.u0, {.min = 0, .min_exclusive = true});
    base_.v0 = p.number("v0", 12 * base_.R0, {.min = 0, .min_exclusive = true});
    base_.max_tilt = p.number("max_tilt_deg", 80, {.min = 0, .max = 90, .min_exclusive = true, .max_exclusive = true}) * kDegree;

    if (const toml::table* wind = p.table("wind")) {
      Parameters w(*wind, "model.wind");
      wind_.type = w.choice("type", "none", {"none", "uniform", "rotating", "grid"});
      auto velocity = w.numbers("velocity", {0, 0}, 2);
      wind_.uniform = Vec3(velocity[0], velocity[1], 0);
      // Or as a weather report gives it (what an ensemble samples): the speed and the direction
      // the wind blows from, clockwise from north (a wind from 270° blows towards +x).
      if (w.has("speed") || w.has("direction_deg")) {
        if (wind_.type != "uniform") w.fail("speed", "speed and direction_deg apply to type = \"uniform\"");
        if (w.has("velocity")) w.fail("velocity", "give either velocity or speed and direction_deg");
        const double speed = w.required_number("speed", {.min = 0});
        const double from = w.required_number("direction_deg") * kDegree;
        wind_.uniform = Vec3(-speed * std::sin(from), -speed * std::cos(from), 0);
      }
      auto center = w.numbers("center", {}, std::nullopt);
      if (!center.empty() && center.size() != 2) throw InputError("[model.wind] center: expected [x, y]");
      wind_.has_center = !center.empty();
      if (wind_.has_center) wind_.center = Vec3(center[0], center[1], 0);
      wind_.scale = w.number("scale", 1e-3);
      if (wind_.type == "grid") {
        if (!w.has("u_file") || !w.has("v_file"))
          throw InputError("[model.wind] type = \"grid\" needs u_file and v_file (ESRI ASCII grids)");
        wind_u_file_ = w.path("u_file");
        wind_v_file_ = w.path("v_file");
        wind_.u = read_dem(wind_u_file_);
        wind_.v = read_dem(wind_v_file_);
      } else {
        w.accept("u_file");
        w.accept("v_file");
      }
      w.reject_unknown();
    }
    if (const toml::table* fuel = p.table("fuel")) {
      Parameters f(*fuel, "model.fuel");
      const std::filesystem::path map = f.path("map");
      std::vector<std::string> names;
      if (auto* arr = (*fuel)["presets"].as_array()) {
        f.accept("presets");
        for (auto& node : *arr) {
          auto s = node.value<std::string>();
          if (!s) throw InputError("[model.fuel] presets: expected an array of preset names");
          names.push_back(*s);
        }
      }
      if (names.empty()) names.push_back(preset_name);
      fuels_.clear();
      for (auto& n : names) {
        try {
          BalbiParameters q = preset(n);
          q.max_tilt = base_.max_tilt;
          q.u0 = base_.u0;
          fuels_.push_back(q);
        } catch (const std::invalid_argument& e) {
          throw InputError(std::string("[model.fuel] presets: ") + e.what());
        }
      }
      fuel_file_ = map;
      if (!map.empty()) fuel_map_ = read_dem(map);
      f.reject_unknown();
    }
    if (const toml::table* arrival = p.table("arrival")) {
      Parameters a(*arrival, "model.arrival");
      arrival_cell_ = a.number("cell_size", 0, {.min = 0});
      const std::filesystem::path like = a.path("like");
      arrival_like_file_ = like;
      if (!like.empty()) arrival_like_ = read_dem(like);
      a.reject_unknown();
    }
    // The rasters of one case share one coordinate system, which the outputs then carry.
    std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters;
    if (fuel_map_.cols > 0) rasters.emplace_back(&fuel_map_, fuel_file_);
    if (wind_.u.cols > 0) rasters.emplace_back(&wind_.u, wind_u_file_);
    if (wind_.v.cols > 0) rasters.emplace_back(&wind_.v, wind_v_file_);
    if (arrival_like_.cols > 0) rasters.emplace_back(&arrival_like_, arrival_like_file_);
    crs_.clear();
    const HeightGrid* first = nullptr;
    std::filesystem::path first_file;
    for (const auto& [grid, file] : rasters) {
      if (grid->crs.empty()) continue;
      if (first) require_same_crs(*first, first_file, *grid, file);
      else {
        first = grid;
        first_file = file;
        crs_ = grid->crs;
      }
    }
    p.reject_unknown();
  }

  VelocityField compute(const StepContext& context) override {
    const SurfaceMesh& mesh = context.mesh();
    const VectorField& conormal = context.conormal();
    const VectorField& normals = context.vertex_normals();
    if (!wind_.has_center) {
      BoundingBox box = bounding_box(mesh);
      wind_.center = 0.5 * (box.min + box.max);
      wind_.has_center = true;
    }
    if (context.is_terrain() && !arrival_.initialised()) arrival_.initialise(mesh, arrival_cell_, arrival_like_, context.mesh_size());

    ScalarField speed(mesh.n_vertices(), 0.0);
    auto rate_at = [&](int v) {
      const Vec3& x = mesh.point(VertexHandle(v));
      const BalbiParameters* fuel = fuel_at(x);
      if (!fuel) return 0.0;  // not burnable: the front stops here
      const Vec3& n_sigma = conormal[v];
      if (n_sigma.sqrnorm() == 0) return fuel->R0;
      const Vec3& normal = normals[v];
      // ∇_S s · n_Σ = e3 · n_Σ because n_Σ is tangent (∇_S s = e3 − (e3·N)N).
      double slope_term = n_sigma[2];
      double wind_term = OpenMesh::dot(wind_.at(x), n_sigma);
      double tan_gamma = tan_tilt(slope_term, std::abs(normal[2]), wind_term, *fuel);
      return rate_of_spread(std::atan(tan_gamma), *fuel);
    };
    // A sub-step in a narrow band needs R at the band's vertices only, and no metrics or fields.
    if (const std::span<const int> active = context.active_vertices(); !active.empty()) {
      for (int v : active) speed[v] = rate_at(v);
      return VelocityField::normal(std::move(speed));
    }
    for (auto v : mesh.vertices()) speed[v.idx()] = rate_at(v.idx());

    VelocityField field = VelocityField::normal(speed);
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
    // Over the whole landscape too (R is defined everywhere through the extended n_Σ): the speed
    // field a figure of S coloured by R shows, a statistic that does not depend on where the front is.
    double all_sum = 0, all_max = 0;
    for (double r : speed) all_sum += r, all_max = std::max(all_max, r);
    field.metrics = {{"ros_min", count ? lo : 0.0},
                     {"ros_mean", count ? sum / double(count) : 0.0},
                     {"ros_max", hi},
                     {"ros_all_mean", speed.empty() ? 0.0 : all_sum / double(speed.size())},
                     {"ros_all_max", all_max}};
    field.point_fields.emplace_back("rate_of_spread", speed);
    if (arrival_.initialised()) field.point_fields.emplace_back("arrival_time", arrival_.sample_at_vertices(mesh));
    return field;
  }

  void end_step(const StepOutcome& outcome) override {
    if (arrival_.initialised())
      arrival_.update(outcome.mesh, outcome.distance, outcome.phi_next, outcome.time, outcome.dt, outcome.changed);
  }

  // What a resumed run needs to continue exactly: the arrival times so far and the rotating wind's
  // centre (taken from the first mesh's bounding box when the case does not give it).
  void save_state(ModelState& state) const override {
    state.version = 1;
    arrival_.save(state);
    if (wind_.has_center) state.set("wind.center", std::vector<double>{wind_.center[0], wind_.center[1], wind_.center[2]});
  }

  void load_state(const ModelState& state) override {
    if (state.version != 1)
      throw InputError(fmt::format("fire model state version {} (this plugin reads version 1)", state.version));
    arrival_.load(state);
    if (state.has("wind.center")) {
      const auto& c = state.numbers("wind.center");
      if (c.size() != 3) throw InputError("fire model state: wind.center needs 3 numbers");
      wind_.center = Vec3(c[0], c[1], c[2]);
      wind_.has_center = true;
    }
  }

  void finish(const std::filesystem::path& output_dir) override {
    if (arrival_.initialised() && !output_dir.empty()) arrival_.write(output_dir / "arrival_time.asc", crs_);
  }

 private:
  // Fuel at a point: the uniform fuel, or the map's code (0 = not burnable → null).
  const BalbiParameters* fuel_at(const Vec3& x) const {
    if (fuel_map_.cols == 0) return fuels_.empty() ? &base_ : &fuels_.front();
    long code = std::lround(raster_nearest(fuel_map_, x[0], x[1]));
    if (code <= 0 || std::size_t(code) > fuels_.size()) return nullptr;
    return &fuels_[std::size_t(code) - 1];
  }

  BalbiParameters base_;
  std::vector<BalbiParameters> fuels_;
  HeightGrid fuel_map_;
  WindField wind_;
  double arrival_cell_ = 0;
  HeightGrid arrival_like_;
  std::string crs_;
  std::filesystem::path fuel_file_, wind_u_file_, wind_v_file_, arrival_like_file_;  ///< the coordinate system of the model's rasters (WKT; "" when none says), for its outputs
  ArrivalRaster arrival_;
};

}  // namespace
}  // namespace bodyfit::fire

BODYFIT_PLUGIN(bodyfit::fire::FireModel)
