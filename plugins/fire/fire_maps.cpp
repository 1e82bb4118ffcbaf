#include "fire_maps.hpp"

#include <bodyfit/error.hpp>

#include <bodyfit/geometry.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodyfit::fire {
namespace {

/// Barycentric coordinates of (x, y) in the plan view of the triangle p, when it lies inside.
bool plan_barycentric(const std::array<Vec3, 3>& p, double x, double y, std::array<double, 3>& bary) {
  const double det = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
  if (det == 0) return false;
  const double l1 = ((x - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (y - p[0][1])) / det;
  const double l2 = ((p[1][0] - p[0][0]) * (y - p[0][1]) - (x - p[0][0]) * (p[1][1] - p[0][1])) / det;
  const double l0 = 1 - l1 - l2;
  constexpr double eps = -1e-9;
  if (l0 < eps || l1 < eps || l2 < eps) return false;
  bary = {l0, l1, l2};
  return true;
}

// Faces bucketed on a regular grid in plan view, to find the face above a point (x, y) of a
// terrain (a height field: its projection on the plane is one-to-one). The buckets are one array
// (offsets per cell), each holding its faces in index order: the first face found is the same
// however the buckets were filled.
class PlanLocator {
 public:
  PlanLocator(const SurfaceMesh& mesh, double cell) : mesh_(mesh) {
    BoundingBox box = bounding_box(mesh);
    x0_ = box.min[0];
    y0_ = box.min[1];
    cell_ = cell > 0 ? cell : 1.0;
    nx_ = std::max<long>(1, long(std::ceil((box.max[0] - x0_) / cell_)) + 1);
    ny_ = std::max<long>(1, long(std::ceil((box.max[1] - y0_) / cell_)) + 1);
    // Each face's range of cells (i0, i1, j0, j1; empty for a deleted face), found in parallel.
    const int nf = int(mesh.n_faces());
    std::vector<std::array<long, 4>> ranges(std::size_t(nf), {0, -1, 0, -1});
    tbb::parallel_for(0, nf, [&](int k) {
      const FaceHandle f(k);
      if (mesh.status(f).deleted()) return;
      auto p = face_points(mesh, f);
      ranges[std::size_t(k)] = {index(std::min({p[0][0], p[1][0], p[2][0]}), x0_, nx_),
                                index(std::max({p[0][0], p[1][0], p[2][0]}), x0_, nx_),
                                index(std::min({p[0][1], p[1][1], p[2][1]}), y0_, ny_),
                                index(std::max({p[0][1], p[1][1], p[2][1]}), y0_, ny_)};
    });
    auto for_cells = [&](const std::array<long, 4>& r, auto&& visit) {
      for (long j = r[2]; j <= r[3]; ++j)
        for (long i = r[0]; i <= r[1]; ++i) visit(std::size_t(j * nx_ + i));
    };
    start_.assign(std::size_t(nx_ * ny_) + 1, 0);
    for (const auto& r : ranges) for_cells(r, [&](std::size_t c) { ++start_[c + 1]; });
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    faces_.resize(start_.back());
    std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
    for (int k = 0; k < nf; ++k) for_cells(ranges[std::size_t(k)], [&](std::size_t c) { faces_[next[c]++] = k; });
  }

  /// The face above (x, y) and the barycentric coordinates there; invalid face when outside.
  FaceHandle locate(double x, double y, std::array<double, 3>& bary) const {
    const std::size_t c = std::size_t(index(y, y0_, ny_) * nx_ + index(x, x0_, nx_));
    for (std::size_t k = start_[c]; k < start_[c + 1]; ++k)
      if (plan_barycentric(face_points(mesh_, FaceHandle(faces_[k])), x, y, bary)) return FaceHandle(faces_[k]);
    return FaceHandle();
  }

 private:
  long index(double v, double origin, long n) const {
    return std::clamp(long(std::floor((v - origin) / cell_)), 0L, n - 1);
  }
  const SurfaceMesh& mesh_;
  double x0_ = 0, y0_ = 0, cell_ = 1;
  long nx_ = 1, ny_ = 1;
  std::vector<std::size_t> start_;  ///< cell c's faces: faces_[start_[c] .. start_[c + 1])
  std::vector<int> faces_;
};

double cell_center_x(const HeightGrid& g, std::size_t col) { return g.x_origin + (double(col) + 0.5) * g.cell_size; }
double cell_center_y(const HeightGrid& g, std::size_t row) {
  return g.y_origin + (double(g.rows - 1 - row) + 0.5) * g.cell_size;  // row 0 is the northernmost
}

}  // namespace

double raster_nearest(const HeightGrid& grid, double x, double y) {
  if (grid.cols == 0) return std::numeric_limits<double>::quiet_NaN();
  long col = std::clamp(long(std::floor((x - grid.x_origin) / grid.cell_size)), 0L, long(grid.cols) - 1);
  long row_from_south = std::clamp(long(std::floor((y - grid.y_origin) / grid.cell_size)), 0L, long(grid.rows) - 1);
  return grid.at(grid.rows - 1 - std::size_t(row_from_south), std::size_t(col));
}

void ArrivalRaster::initialise(const SurfaceMesh& mesh, double cell_size, const HeightGrid& like, double mesh_size) {
  if (like.cols > 0) {
    grid_ = like;
  } else {
    BoundingBox box = bounding_box(mesh);
    grid_ = HeightGrid{};
    grid_.cell_size = cell_size > 0 ? cell_size : mesh_size;
    grid_.x_origin = box.min[0];
    grid_.y_origin = box.min[1];
    grid_.cols = std::max<std::size_t>(1, std::size_t(std::ceil((box.max[0] - box.min[0]) / grid_.cell_size)));
    grid_.rows = std::max<std::size_t>(1, std::size_t(std::ceil((box.max[1] - box.min[1]) / grid_.cell_size)));
  }
  grid_.nodata = -9999;
  grid_.heights.assign(grid_.cols * grid_.rows, std::numeric_limits<double>::quiet_NaN());
  rate_ = grid_;
  recorded_.assign(recorded_names_.size(), grid_);
}

void ArrivalRaster::save(ModelState& state) const {
  if (!initialised()) return;
  state.set("arrival.size", std::vector<std::int64_t>{std::int64_t(grid_.cols), std::int64_t(grid_.rows)});
  state.set("arrival.frame", std::vector<double>{grid_.x_origin, grid_.y_origin, grid_.cell_size, grid_.nodata});
  state.set("arrival.times", grid_.heights);
  state.set("arrival.rates", rate_.heights);
  for (std::size_t k = 0; k < recorded_.size(); ++k) state.set("arrival.recorded." + recorded_names_[k], recorded_[k].heights);
}

void ArrivalRaster::load(const ModelState& state) {
  grid_ = HeightGrid{};
  if (!state.has("arrival.size")) return;
  const auto& size = state.integers("arrival.size");
  const auto& frame = state.numbers("arrival.frame");
  const auto& times = state.numbers("arrival.times");
  if (size.size() != 2 || frame.size() != 4 || size[0] <= 0 || size[1] <= 0 ||
      times.size() != std::size_t(size[0]) * std::size_t(size[1]))
    throw InputError("fire model state: the arrival-time raster is inconsistent");
  grid_.cols = std::size_t(size[0]);
  grid_.rows = std::size_t(size[1]);
  grid_.x_origin = frame[0], grid_.y_origin = frame[1], grid_.cell_size = frame[2], grid_.nodata = frame[3];
  grid_.heights = times;
  rate_ = grid_;
  // States written before the rate raster existed have none: those rates stay unknown (NaN).
  if (state.has("arrival.rates") && state.numbers("arrival.rates").size() == times.size())
    rate_.heights = state.numbers("arrival.rates");
  else
    rate_.heights.assign(times.size(), std::numeric_limits<double>::quiet_NaN());
  recorded_.assign(recorded_names_.size(), rate_);
  for (std::size_t k = 0; k < recorded_.size(); ++k) {
    const std::string key = "arrival.recorded." + recorded_names_[k];
    if (state.has(key) && state.numbers(key).size() == times.size()) recorded_[k].heights = state.numbers(key);
    else recorded_[k].heights.assign(times.size(), std::numeric_limits<double>::quiet_NaN());
  }
  swept_ = true;  // the state comes from a run past its first update
}

void ArrivalRaster::update(const SurfaceMesh& mesh, const ScalarField& distance, const ScalarField& phi_next,
                           double time, double dt, std::span<const int> changed, const ScalarField* speed,
                           std::span<const ScalarField* const> recorded) {
  auto reach = [&](double& arrival, FaceHandle f, const std::array<double, 3>& bary) {
    auto vs = face_vertices(mesh, f);
    double d = 0, phi = 0;
    for (int k = 0; k < 3; ++k) {
      d += bary[k] * distance[vs[k].idx()];
      phi += bary[k] * phi_next[vs[k].idx()];
    }
    auto at_crossing = [&](const ScalarField& field) {
      double value = 0;
      for (int k = 0; k < 3; ++k) value += bary[k] * field[vs[k].idx()];
      return value;
    };
    if (d <= 0) {
      arrival = time;  // already burnt at t^n (the initial region)
    } else if (phi <= 0) {
      arrival = time + dt * std::clamp(d / (d - phi), 0.0, 1.0);
      const std::size_t cell = std::size_t(&arrival - grid_.heights.data());
      if (speed) rate_.heights[cell] = at_crossing(*speed);
      for (std::size_t k = 0; k < recorded.size() && k < recorded_.size(); ++k)
        if (recorded[k]) recorded_[k].heights[cell] = at_crossing(*recorded[k]);
    }
  };
  if (!swept_ || changed.empty()) {
    PlanLocator locator(mesh, 2 * edge_length_stats(mesh).mean);
    // Every cell on its own (it writes its own arrival, rate and recorded values): rows in parallel.
    tbb::parallel_for(std::size_t(0), grid_.rows, [&](std::size_t row) {
      for (std::size_t col = 0; col < grid_.cols; ++col) {
        double& arrival = grid_.heights[row * grid_.cols + col];
        if (!std::isnan(arrival)) continue;
        std::array<double, 3> bary;
        FaceHandle f = locator.locate(cell_center_x(grid_, col), cell_center_y(grid_, row), bary);
        if (f.is_valid()) reach(arrival, f, bary);
      }
    });
    swept_ = true;
    return;
  }
  // The cells whose centres lie under a face around a changed vertex, each face once.
  face_seen_.resize(mesh.n_faces(), 0);
  const std::uint32_t epoch = ++epoch_;
  const double cell = grid_.cell_size;
  for (int v : changed)
    for (FaceHandle f : mesh.vf_range(VertexHandle(v))) {
      if (face_seen_[f.idx()] == epoch) continue;
      face_seen_[f.idx()] = epoch;
      const auto p = face_points(mesh, f);
      const double xmin = std::min({p[0][0], p[1][0], p[2][0]}), xmax = std::max({p[0][0], p[1][0], p[2][0]});
      const double ymin = std::min({p[0][1], p[1][1], p[2][1]}), ymax = std::max({p[0][1], p[1][1], p[2][1]});
      // Columns with x_origin + (c + ½)·cell in [xmin, xmax]; rows likewise from the south.
      const long c0 = std::max(0L, long(std::ceil((xmin - grid_.x_origin) / cell - 0.5)));
      const long c1 = std::min(long(grid_.cols) - 1, long(std::floor((xmax - grid_.x_origin) / cell - 0.5)));
      const long s0 = std::max(0L, long(std::ceil((ymin - grid_.y_origin) / cell - 0.5)));
      const long s1 = std::min(long(grid_.rows) - 1, long(std::floor((ymax - grid_.y_origin) / cell - 0.5)));
      for (long south = s0; south <= s1; ++south)
        for (long col = c0; col <= c1; ++col) {
          const std::size_t row = grid_.rows - 1 - std::size_t(south);
          double& arrival = grid_.heights[row * grid_.cols + std::size_t(col)];
          if (!std::isnan(arrival)) continue;
          std::array<double, 3> bary;
          if (plan_barycentric(p, cell_center_x(grid_, std::size_t(col)), cell_center_y(grid_, row), bary))
            reach(arrival, f, bary);
        }
    }
}

ScalarField ArrivalRaster::sample_at_vertices(const SurfaceMesh& mesh) const {
  ScalarField values(mesh.n_vertices(), std::numeric_limits<double>::quiet_NaN());
  for (auto v : mesh.vertices()) values[v.idx()] = raster_nearest(grid_, mesh.point(v)[0], mesh.point(v)[1]);
  return values;
}

GridField grid_field(const HeightGrid& grid, std::string description,
                     std::vector<std::pair<std::string, std::string>> items, const std::string& crs) {
  GridField field;
  field.cols = grid.cols, field.rows = grid.rows;
  field.x_origin = grid.x_origin, field.y_origin = grid.y_origin;
  field.cell_size = grid.cell_size;
  field.values = grid.heights;
  for (double& v : field.values)
    if (v == grid.nodata) v = std::numeric_limits<double>::quiet_NaN();
  field.crs = crs;
  field.description = std::move(description);
  field.items = std::move(items);
  return field;
}

}  // namespace bodyfit::fire
