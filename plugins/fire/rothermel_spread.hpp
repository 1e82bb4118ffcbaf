#pragma once
// Rothermel's spread in the fire model (`spread = "rothermel"`): the fuel beds of a fuel table
// under the case's moistures, the canopy over them (crown fire, the wind's shelter), the fire
// ellipse at the mesh's vertices, and the intensity rasters of a run.
#include "crown.hpp"
#include "fire_maps.hpp"
#include "fuel.hpp"
#include "moisture.hpp"
#include "rothermel.hpp"
#include "wind.hpp"

#include <bodyfit/model_outputs.hpp>
#include <bodyfit/parameters.hpp>

#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace bodyfit::fire {

/// How the model reads a raster of the case (checked against the surface's coordinate system and
/// warped like the DEM), or a band of a FARSITE landscape when one is given.
using ModelRasterReader =
    std::function<HeightGrid(const std::filesystem::path&, Resampling, std::optional<LandscapeBand>)>;

class RothermelSpread {
 public:
  /// Reads Rothermel's keys of [model] (fuel table and model or map or landscape, moistures,
  /// canopy, limit_effective_wind) and refuses Balbi's. The fuel map itself is the model's.
  void configure(Parameters& p, const ModelRasterReader& read);

  /// The fuel of a code of the fuel map: an index of the table's models, −1 when it has none.
  int fuel_of_code(long long code) const;
  const FuelTable& table() const { return table_; }
  /// [model] landscape ("" when none): its fuel band is the fuel map.
  const std::filesystem::path& landscape() const { return landscape_file_; }
  bool has_canopy() const { return has_canopy_; }
  /// The fields the arrival raster records as the front crosses each cell, in recorded()'s order.
  std::vector<std::string> recorded_names() const;
  /// The rasters read (moistures, canopy), for the case's coordinate-system check.
  std::vector<std::pair<const HeightGrid*, std::filesystem::path>> rasters() const;

  /// The fire ellipse at the vertices `active` (all when empty) at `time`: each vertex's fuel
  /// (`fuel_at`: an index, −1 for none), its terrain `normals`, the wind at its height.
  void update(const SurfaceMesh& mesh, const VectorField& normals, std::span<const int> active, double time,
              std::optional<double> clock_start, const WindField& wind, WindHeight height,
              const std::function<int(double, double)>& fuel_at);
  /// The normal speed at vertex v for the front direction n (unit; 0: the flank rate).
  double rate(int v, const Vec3& n) const;
  /// Per-vertex fields the arrival raster records (null where not current for `n` vertices).
  std::vector<const ScalarField*> recorded(std::size_t n) const;
  /// Heat per unit area, fireline intensity, flame length and, with a canopy, the fire type of
  /// the cells `arrival` saw burn.
  void write_grids(ModelOutputs& outputs, const ArrivalRaster& arrival,
                   const std::vector<std::pair<std::string, std::string>>& items, const std::string& crs) const;

 private:
  /// A canopy quantity: a number, or a raster (of [model.canopy] or a band of the landscape).
  struct CanopyLayer {
    double value = 0;
    HeightGrid map{};
    std::filesystem::path file{};
    double at(double x, double y) const { return map.cols > 0 ? map.sample(x, y) : value; }
  };

  void configure_canopy(Parameters& p, const ModelRasterReader& read);
  Canopy canopy_at(double x, double y) const;
  Sheltering sheltering_at(double x, double y) const;

  FuelTable table_;
  MoistureField moisture_;
  std::vector<FuelModel> models_;  ///< the fuels the run may meet
  std::vector<SurfaceFire> beds_;  ///< their beds under constant moistures, or at beds_time_
  double beds_time_ = std::numeric_limits<double>::quiet_NaN();
  std::unordered_map<long long, int> code_index_;  ///< fuel code → models_ index
  SpreadOptions options_;
  std::vector<HeadSpread> spreads_;  ///< the ellipse at the vertices (update)
  ScalarField heats_;                ///< heat per unit area at the vertices, kJ/m²
  ScalarField types_;                ///< with a canopy: FireType at the vertices
  bool has_canopy_ = false;
  Canopy canopy_;  ///< its foliar moisture
  CanopyLayer base_height_layer_, bulk_density_layer_, cover_layer_, height_layer_;
  std::filesystem::path landscape_file_;
  FuelModel fm10_;         ///< Anderson's model 10 (Rothermel's 1991 crown rate)
  SurfaceFire fm10_bed_;   ///< under the constant moistures, or at beds_time_
};

}  // namespace bodyfit::fire
