#pragma once
// Spatial data of the fire model: wind fields, raster lookups and the arrival-time raster.
#include <bodyfit/generators.hpp>
#include <bodyfit/mesh.hpp>
#include <bodyfit/model_state.hpp>

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>
#include <string>

namespace bodyfit::fire {

/// Value of the cell containing (x, y) (clamped to the raster).
double raster_nearest(const HeightGrid& grid, double x, double y);

/// Horizontal wind U(x) in m/s.
struct WindField {
  std::string type = "none";  ///< none | uniform | rotating | grid
  Vec3 uniform{0, 0, 0};
  Vec3 center{0, 0, 0};
  bool has_center = false;
  double scale = 1e-3;        ///< rotating: U = scale·(y − yc, −(x − xc), 0)
  HeightGrid u, v;            ///< grid: components on rasters
  Vec3 at(const Vec3& x) const;
};

/// Arrival time of the front on a fixed raster, interpolated within each step: a cell centre that
/// is outside G at t^n (d > 0) and inside at t^n + Δt (φ^{n+1} ≤ 0) is reached at
/// t^n + Δt·d/(d − φ^{n+1}), the zero of the linear interpolation in time of the level set.
/// Cells never reached keep NODATA. The raster is the DEM's (when given) or covers the mesh's
/// bounding box in plan view.
class ArrivalRaster {
 public:
  bool initialised() const { return grid_.cols > 0; }
  void initialise(const SurfaceMesh& mesh, double cell_size, const HeightGrid& like, double mesh_size);
  /// One (sub-)step: φ went from `distance` to `phi_next`, changing only at the vertices `changed`
  /// (all when empty). After the first update, which sweeps every cell (the initial region), only
  /// the cells under the faces around `changed` can be reached, and only those are visited.
  void update(const SurfaceMesh& mesh, const ScalarField& distance, const ScalarField& phi_next, double time, double dt,
              std::span<const int> changed = {});
  /// Arrival time at the vertices (bilinear over reached cells; NaN where none is reached yet).
  ScalarField sample_at_vertices(const SurfaceMesh& mesh) const;
  /// As an ESRI ASCII grid, with a .prj beside it when `crs` (WKT) is known.
  void write(const std::filesystem::path& file, const std::string& crs = {}) const;
  const HeightGrid& grid() const { return grid_; }
  /// Into / back from a checkpoint's model state (keys "arrival.*"); load leaves the raster
  /// uninitialised when the state has none.
  void save(ModelState& state) const;
  void load(const ModelState& state);

 private:
  HeightGrid grid_;  ///< heights hold the arrival times (NaN = not reached)
  bool swept_ = false;  ///< every cell visited once (the initial region is in the raster)
  std::vector<std::uint32_t> face_seen_;  ///< = epoch_ for the faces visited by this update
  std::uint32_t epoch_ = 0;
};

}  // namespace bodyfit::fire
