#pragma once
// Spatial data of the fire model: raster lookups and the arrival-time raster (the wind: wind.hpp).
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/mesh.hpp>
#include <bodyfit/model_outputs.hpp>
#include <bodyfit/model_state.hpp>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace bodyfit::fire {

/// A raster of the model as a grid output, in the coordinate system `crs` (NODATA cells as NaN).
GridField grid_field(const HeightGrid& grid, std::string description,
                     std::vector<std::pair<std::string, std::string>> items, const std::string& crs);

/// Value of the cell containing (x, y) (clamped to the raster).
double raster_nearest(const HeightGrid& grid, double x, double y);

/// Arrival time of the front on a fixed raster, interpolated within each step: a cell centre that
/// is outside G at t^n (d > 0) and inside at t^n + Δt (φ^{n+1} ≤ 0) is reached at
/// t^n + Δt·d/(d − φ^{n+1}), the zero of the linear interpolation in time of the level set.
/// Cells never reached keep NODATA. The raster is the DEM's (when given) or covers the mesh's
/// bounding box in plan view. Beside it, the rate of spread at which each cell burnt: the normal
/// speed of the step that reached it, interpolated at the cell centre (NaN for the cells of the
/// initial region, which did not burn by spreading, and for cells never reached).
class ArrivalRaster {
 public:
  bool initialised() const { return grid_.cols > 0; }
  void initialise(const SurfaceMesh& mesh, double cell_size, const HeightGrid& like, double mesh_size);
  /// One (sub-)step: φ went from `distance` to `phi_next`, changing only at the vertices `changed`
  /// (all when empty). After the first update, which sweeps every cell (the initial region), only
  /// the cells under the faces around `changed` can be reached, and only those are visited.
  /// `speed`: the rate of spread at the vertices of `mesh` in this step (null: not recorded).
  /// `recorded`: more fields at the vertices, recorded like the rate (the names set by record()).
  void update(const SurfaceMesh& mesh, const ScalarField& distance, const ScalarField& phi_next, double time, double dt,
              std::span<const int> changed = {}, const ScalarField* speed = nullptr,
              std::span<const ScalarField* const> recorded = {});
  /// The fields recorded besides the rate as the front crosses each cell (before initialise()).
  void record(std::vector<std::string> names) { recorded_names_ = std::move(names); }
  /// A recorded field on the raster's cells (NaN: not reached, or burning at the start).
  const HeightGrid& recorded(std::size_t k) const { return recorded_[k]; }
  /// Arrival time at the vertices (bilinear over reached cells; NaN where none is reached yet).
  ScalarField sample_at_vertices(const SurfaceMesh& mesh) const;
  /// Arrival times (s; NaN: not reached) and rates of spread (m/s; NaN: none) on the same raster.
  const HeightGrid& grid() const { return grid_; }
  const HeightGrid& rate_grid() const { return rate_; }
  /// Into / back from a checkpoint's model state (keys "arrival.*"); load leaves the raster
  /// uninitialised when the state has none.
  void save(ModelState& state) const;
  void load(const ModelState& state);

 private:
  HeightGrid grid_;  ///< heights hold the arrival times (NaN = not reached)
  HeightGrid rate_;  ///< the same frame; heights hold the rates of spread
  std::vector<std::string> recorded_names_;
  std::vector<HeightGrid> recorded_;  ///< the same frame, one per recorded_names_
  bool swept_ = false;  ///< every cell visited once (the initial region is in the raster)
  std::vector<std::uint32_t> face_seen_;  ///< = epoch_ for the faces visited by this update
  std::uint32_t epoch_ = 0;
};

}  // namespace bodyfit::fire
