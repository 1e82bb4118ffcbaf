#include "rothermel_spread.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace bodyfit::fire {

// Rothermel's fuel beds: the fuel table's models under the case's moistures; Balbi's keys refused.
void RothermelSpread::configure(Parameters& p, const ModelRasterReader& read) {
  landscape_file_.clear();
  p.forbid({"preset", "R0", "A", "u0", "v0", "max_tilt_deg"},
           "to spread = \"rothermel\" (Balbi's parameters: Rothermel's come from the fuel table)");
  options_.limit_effective_wind = p.boolean("limit_effective_wind");
  moisture_ = read_moisture(p.section("moisture"), [&](const std::filesystem::path& file) {
    return read(file, Resampling::bilinear, std::nullopt);
  });
  Parameters& f = p.section("fuel");
  f.forbid({"presets"}, "to spread = \"rothermel\" (Balbi's parameter sets: Rothermel's fuels are the table's)");
  if (f.has("table_file")) {
    if (f.has("table")) f.fail("table", "give either fuel.table or fuel.table_file");
    table_ = read_fuel_table(f.path("table_file"));
  } else {
    table_ = fuel_table(f.choice("table"));
  }
  beds_.clear();
  models_.clear();
  code_index_.clear();
  beds_time_ = std::numeric_limits<double>::quiet_NaN();
  if (p.has("landscape")) {
    landscape_file_ = p.path("landscape");
    if (f.has("model") || f.has("map"))
      f.fail(f.has("model") ? "model" : "map", "the fuel comes from [model] landscape (its fuel band): give either");
  } else if (f.has("model") == f.has("map")) {
    f.fail("expected either fuel.model (one fuel everywhere, e.g. \"GR2\"), fuel.map (a raster of the fuel "
           "table's codes) or [model] landscape (a FARSITE landscape)");
  }
  auto add_bed = [&](const FuelModel& m) {
    code_index_[m.code] = int(models_.size());
    models_.push_back(m);
    if (moisture_.kind() != MoistureField::Kind::constant) return;  // per time or per vertex
    beds_.push_back(surface_fire(m, moisture_.at(0, 0, 0, m.code)));
    const SurfaceFire& bed = beds_.back();
    if (!bed.extinct.empty() && m.burnable()) spdlog::warn("{}", bed.extinct);
  };
  configure_canopy(p, read);
  fm10_ = *fuel_table("anderson13").find("FM10");
  if (moisture_.kind() == MoistureField::Kind::constant) fm10_bed_ = surface_fire(fm10_, moisture_.at(0, 0, 0));
  if (f.has("model")) {
    const std::string name = f.string("model");
    const FuelModel* m = table_.find(name);
    if (!m) f.fail("model", fmt::format("'{}' is not a model of the fuel table {}", name, table_.source));
    add_bed(*m);
  } else {
    for (const FuelModel& m : table_.models) add_bed(m);
  }
}

// [model.canopy]: the canopy base height and bulk density (numbers or rasters) and the foliar
// moisture, for crown fire; no table, no crown fire.
void RothermelSpread::configure_canopy(Parameters& p, const ModelRasterReader& read) {
  canopy_ = Canopy{};
  for (CanopyLayer* layer : {&base_height_layer_, &bulk_density_layer_, &cover_layer_, &height_layer_}) *layer = {};
  const bool landscape = !landscape_file_.empty();
  has_canopy_ = p.has("canopy") || landscape;
  if (!has_canopy_) return;
  Parameters& c = p.section("canopy");
  // A quantity: a number, a raster, or a band of the landscape (in that order of precedence).
  auto read_layer = [&](const char* key, CanopyLayer& layer, std::optional<LandscapeBand> band, bool required) {
    const std::string map_key = std::string(key) + "_map";
    if (c.has(map_key)) {
      if (c.has(key)) c.fail(map_key, fmt::format("give either {} or {}, not both", key, map_key));
      layer.file = c.path(map_key);
      layer.map = read(layer.file, Resampling::bilinear, std::nullopt);
    } else if (c.has(key) || (required && !landscape)) {
      layer.value = c.required_number(key);
      return;
    } else if (band && landscape) {
      layer.file = landscape_file_;
      layer.map = read(landscape_file_, Resampling::bilinear, band);
    } else {
      return;
    }
    // A canopy raster holds heights, densities or a cover: none is negative.
    for (std::size_t row = 0; row < layer.map.rows; ++row)
      for (std::size_t col = 0; col < layer.map.cols; ++col)
        if (layer.map.valid(row, col) && layer.map.at(row, col) < 0)
          throw InputError(fmt::format("{}: the {} of the cell at row {}, column {} is negative ({})",
                                       layer.file.string(), key, row + 1, col + 1, layer.map.at(row, col)));
    fill_nodata(layer.map);
  };
  read_layer("base_height", base_height_layer_, LandscapeBand::canopy_base_height, true);
  read_layer("bulk_density", bulk_density_layer_, LandscapeBand::canopy_bulk_density, true);
  read_layer("cover", cover_layer_, LandscapeBand::canopy_cover, false);
  read_layer("height", height_layer_, LandscapeBand::canopy_height, false);
  const double foliar = c.number("foliar_moisture");
  const std::string problem = moisture_percent_problem(foliar);
  if (!problem.empty()) c.fail("foliar_moisture", problem);
  canopy_.foliar_moisture = foliar / 100;
}

Canopy RothermelSpread::canopy_at(double x, double y) const {
  Canopy canopy = canopy_;
  canopy.base_height = base_height_layer_.at(x, y);
  canopy.bulk_density = bulk_density_layer_.at(x, y);
  return canopy;
}

// The canopy's shelter from the wind at (x, y): its cover and height, and the crown ratio with
// its base; none without a cover and a height.
Sheltering RothermelSpread::sheltering_at(double x, double y) const {
  const double height = height_layer_.at(x, y), cover = cover_layer_.at(x, y) / 100;
  if (!(height > 0) || !(cover > 0)) return {};
  const double base = std::clamp(base_height_layer_.at(x, y), 0.0, height);
  return {.cover = cover, .canopy_height = height, .crown_ratio = (height - base) / height};
}

int RothermelSpread::fuel_of_code(long long code) const {
  const auto it = code_index_.find(code);
  return it == code_index_.end() ? -1 : it->second;
}

std::vector<std::string> RothermelSpread::recorded_names() const {
  if (has_canopy_) return {"heat_per_unit_area", "fire_type"};
  return {"heat_per_unit_area"};
}

std::vector<std::pair<const HeightGrid*, std::filesystem::path>> RothermelSpread::rasters() const {
  std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters = moisture_.rasters();
  for (const CanopyLayer* layer : {&base_height_layer_, &bulk_density_layer_, &cover_layer_, &height_layer_})
    if (layer->map.cols > 0) rasters.emplace_back(&layer->map, layer->file);
  return rasters;
}

double RothermelSpread::rate(int v, const Vec3& n) const {
  const HeadSpread& spread = spreads_[std::size_t(v)];
  return n.sqrnorm() == 0 ? spread.flank : ellipse_normal_rate(spread, n);
}

std::vector<const ScalarField*> RothermelSpread::recorded(std::size_t n) const {
  std::vector<const ScalarField*> fields = {heats_.size() == n ? &heats_ : nullptr};
  if (has_canopy_) fields.push_back(types_.size() == n ? &types_ : nullptr);
  return fields;
}

// Rothermel's fire ellipse at the vertices R is needed at (the band's, or all): fuel, slope and
// wind are the vertex's, the direction of the front is applied by ellipse_normal_rate.
void RothermelSpread::update(const SurfaceMesh& mesh, const VectorField& normals, std::span<const int> active, double time,
                             std::optional<double> clock_start, const WindField& wind, WindHeight height,
                             const std::function<int(double, double)>& fuel_at) {
  moisture_.set_clock(clock_start);
  const std::size_t n = mesh.n_vertices();
  spreads_.resize(n);
  heats_.resize(n, 0.0);
  if (has_canopy_) types_.resize(n, double(FireType::surface));
  if (moisture_.kind() == MoistureField::Kind::series && time != beds_time_) {
    // Moistures in time: every fuel's bed at this (sub-)step's time.
    beds_.clear();
    for (const FuelModel& m : models_) beds_.push_back(surface_fire(m, moisture_.at(0, 0, time, m.code), false));
    fm10_bed_ = surface_fire(fm10_, moisture_.at(0, 0, time), false);
    beds_time_ = time;
  }
  const bool per_vertex = moisture_.kind() == MoistureField::Kind::maps;
  auto update_vertex = [&](int v) {
    const std::size_t i = std::size_t(v);
    const Vec3& x = mesh.point(VertexHandle(v));
    const int fuel = fuel_at(x[0], x[1]);
    if (fuel < 0) {
      spreads_[i] = HeadSpread{};
      heats_[i] = 0;
      if (has_canopy_) types_[i] = double(FireType::surface);
      return;
    }
    // Moisture rasters: the bed of this vertex's fuel under its own moistures.
    const FuelModel& model = models_[std::size_t(fuel)];
    const FuelMoisture moisture = per_vertex ? moisture_.at(x[0], x[1], time, model.code) : FuelMoisture{};
    const SurfaceFire bed = per_vertex ? surface_fire(model, moisture, false) : beds_[std::size_t(fuel)];
    const Vec3 wind_here = wind.at(x, time);
    const Sheltering shelter = has_canopy_ ? sheltering_at(x[0], x[1]) : Sheltering{};
    spreads_[i] = head_spread_on_terrain(bed, normals[v], wind_here, midflame_factor(height, bed.depth, shelter),
                                         options_);
    heats_[i] = bed.heat_per_unit_area;
    if (!has_canopy_) return;
    // The crown fire over it: the 20-ft wind (a midflame wind goes back up by the bed's factor).
    const TerrainSlope slope = terrain_slope(normals[v]);
    const CrownFire crown =
        crown_fire(spreads_[i], bed.heat_per_unit_area, canopy_at(x[0], x[1]),
                   per_vertex ? surface_fire(fm10_, moisture, false) : fm10_bed_,
                   tangent_wind(twenty_foot_factor(height, bed.depth, shelter) * wind_here, normals[v]), slope.upslope, slope.tan_slope, options_);
    spreads_[i] = crown.spread;
    types_[i] = double(crown.type);
  };
  // Each vertex on its own: in parallel.
  const std::size_t count = active.empty() ? n : active.size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 128), [&](const auto& range) {
    for (std::size_t k = range.begin(); k < range.end(); ++k) update_vertex(active.empty() ? int(k) : active[k]);
  });
}

// Byram's fireline intensity, flame length and the heat per unit area of the cells that burnt
// (the heat recorded as the front crossed each, times the rate it crossed at), and with a canopy
// the fire type there.
void RothermelSpread::write_grids(ModelOutputs& outputs, const ArrivalRaster& arrival,
                                  const std::vector<std::pair<std::string, std::string>>& items,
                                  const std::string& crs) const {
  const HeightGrid& rate = arrival.rate_grid();
  const HeightGrid& heat = arrival.recorded(0);
  HeightGrid intensity = rate, flame = rate, type = rate;
  for (std::size_t cell = 0; cell < rate.heights.size(); ++cell) {
    const double r = rate.heights[cell], h = heat.heights[cell];
    const bool burnt = std::isfinite(r) && std::isfinite(h);
    intensity.heights[cell] = burnt ? fireline_intensity(h, r) : std::numeric_limits<double>::quiet_NaN();
    flame.heights[cell] = burnt ? flame_length(intensity.heights[cell]) : std::numeric_limits<double>::quiet_NaN();
    if (has_canopy_) {
      const double t = arrival.recorded(1).heights[cell];
      type.heights[cell] = burnt && std::isfinite(t) ? std::round(t) : std::numeric_limits<double>::quiet_NaN();
    }
  }
  outputs.grid("heat_per_unit_area", grid_field(heat, "heat per unit area released, kJ/m² (Rothermel)", items, crs));
  outputs.grid("fireline_intensity",
               grid_field(intensity, "Byram's fireline intensity at which the cell burnt, kW/m", items, crs));
  outputs.grid("flame_length", grid_field(flame, "Byram's flame length at which the cell burnt, m", items, crs));
  if (has_canopy_)
    outputs.grid("fire_type", grid_field(type, "fire type where the cell burnt: 1 surface, 2 passive crown, 3 active "
                                               "crown (Van Wagner 1977, Rothermel 1991)",
                                         items, crs));
}

}  // namespace bodyfit::fire
