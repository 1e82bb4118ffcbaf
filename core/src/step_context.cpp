// StepContext: the read-only view a velocity model gets, with helpers computed on first use.
#include "step_state.hpp"

#include <bodyfit/geometry.hpp>
#include <bodyfit/surface_fem.hpp>

#include <tbb/parallel_for.h>

#include <cmath>
#include <map>
#include <numeric>
#include <mutex>
#include <optional>
#include <stdexcept>

namespace bodyfit {

namespace {

/// S's smooth normal at the vertices `where` that are not `known` yet (then known). Each is
/// found on its own, without a hint from a neighbour, so a normal is the same whichever vertices
/// are asked for together: a band gives the whole surface's values.
void fill_smooth_normals(const SurfaceMesh& mesh, const ReferenceSurface& surface, std::span<const int> where,
                         VectorField& normals, std::vector<char>& known) {
  if (normals.size() != mesh.n_vertices()) {
    normals.assign(mesh.n_vertices(), Vec3(0, 0, 0));
    known.assign(mesh.n_vertices(), 0);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, where.size(), 256), [&](const tbb::blocked_range<std::size_t>& block) {
    for (std::size_t i = block.begin(); i < block.end(); ++i) {
      const auto v = std::size_t(where[i]);
      if (known[v]) continue;
      normals[v] = surface.smooth_normal(surface.closest(mesh.point(VertexHandle(int(v)))));
      known[v] = 1;
    }
  });
}

}  // namespace

struct StepContext::Impl {
  StepState state;
  // Caches: filled on first use under the mutex; never modified afterwards, so the references
  // handed out stay valid for the context's lifetime.
  mutable std::mutex mutex;
  mutable std::optional<double> mesh_size;
  mutable std::optional<std::vector<double>> face_areas;
  mutable std::optional<VectorField> face_normals, vertex_normals, conormal;
  mutable StepGeometry own_geometry;  // S's normals when the context shares none
  mutable std::optional<std::vector<int>> near_front;
  mutable std::optional<Eigen::SparseMatrix<double>> mass, stiffness;
  mutable std::optional<std::vector<double>> lumped_mass;
  mutable std::optional<ScalarField> front_curvature;
  mutable std::map<double, H1Smoother> smoothers;  // one factorisation per length

  const SurfaceMesh& mesh() const { return *state.mesh; }

  const VectorField& vertex_normals_locked() const {
    auto compute = [&](std::optional<VectorField>& cache) -> const VectorField& {
      if (!cache) {
        VectorField normals(mesh().n_vertices(), Vec3(0, 0, 0));
        for (auto v : mesh().vertices()) normals[v.idx()] = vertex_normal(mesh(), v);
        cache = std::move(normals);
      }
      return *cache;
    };
    if (!state.geometry) return compute(vertex_normals);
    std::lock_guard lock(state.geometry->mutex);  // the step's contexts share one copy
    return compute(state.geometry->vertex_normals);
  }
  /// Where the driver reads V: a sub-step's active vertices; in a banded state, the band's
  /// vertices and their ring (d is flat beyond, n_Σ 0); empty when d is whole (every vertex).
  std::span<const int> where_velocity_is_read() const {
    if (!state.active.empty()) return state.active;
    if (!std::isfinite(state.distance_width)) return {};
    if (!near_front) {
      const SurfaceMesh& m = mesh();
      const ScalarField& d = *state.distance;
      std::vector<char> near(m.n_vertices(), 0);
      for (auto v : m.vertices())
        if (std::abs(d[v.idx()]) < state.distance_width) {
          near[v.idx()] = 1;
          for (auto w : m.vv_range(v)) near[w.idx()] = 1;
        }
      std::vector<int> where;
      for (std::size_t v = 0; v < near.size(); ++v)
        if (near[v]) where.push_back(int(v));
      near_front = std::move(where);
    }
    return *near_front;
  }
  const VectorField& surface_normals_locked() const {
    if (!state.surface) return vertex_normals_locked();
    std::span<const int> where = where_velocity_is_read();
    std::vector<int> every;
    if (where.empty()) {
      every.resize(mesh().n_vertices());
      std::iota(every.begin(), every.end(), 0);
      where = every;
    }
    StepGeometry& g = state.geometry ? *state.geometry : own_geometry;
    std::lock_guard lock(g.mutex);  // the step's contexts share one copy
    fill_smooth_normals(mesh(), *state.surface, where, g.surface_normals, g.surface_known);
    return g.surface_normals;
  }
  void couples_every_vertex() const {
    if (state.whole_surface_used) *state.whole_surface_used = true;
  }
  const Eigen::SparseMatrix<double>& mass_locked() const {
    couples_every_vertex();
    if (!mass) mass = bodyfit::mass_matrix(mesh());
    return *mass;
  }
  const Eigen::SparseMatrix<double>& stiffness_locked() const {
    couples_every_vertex();
    if (!stiffness) stiffness = bodyfit::stiffness_matrix(mesh());
    return *stiffness;
  }
  const H1Smoother& smoother_locked(double length) const {
    couples_every_vertex();
    auto it = smoothers.find(length);
    if (it == smoothers.end())
      it = smoothers.emplace(length, H1Smoother(mass_locked(), stiffness_locked(), length, vertex_normals_locked()))
               .first;
    return it->second;
  }
};

StepContext make_step_context(const StepState& state) {
  if (!state.mesh || !state.distance) throw std::invalid_argument("make_step_context: mesh and distance are required");
  if (state.distance->size() != state.mesh->n_vertices())
    throw std::invalid_argument("make_step_context: the distance has one value per vertex");
  auto impl = std::make_unique<StepContext::Impl>();
  impl->state = state;
  return StepContext(std::move(impl));
}

StepContext::StepContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
StepContext::~StepContext() = default;
StepContext::StepContext(StepContext&&) noexcept = default;

StepContext StepContext::standalone(const SurfaceMesh& mesh, const ScalarField& distance, const StandaloneStep& where) {
  return make_step_context(StepState{.mesh = &mesh,
                                     .distance = &distance,
                                     .time = where.time,
                                     .dt = where.dt,
                                     .iteration = where.iteration,
                                     .output_dir = where.output_dir,
                                     .height_field = where.height_field,
                                     .clock_start = where.clock_start,
                                     .active = {},
                                     .geometry = nullptr,
                                     .surface = where.surface,
                                     .whole_surface_used = nullptr});
}

const SurfaceMesh& StepContext::mesh() const { return *impl_->state.mesh; }
const ScalarField& StepContext::distance() const { return *impl_->state.distance; }
double StepContext::time() const { return impl_->state.time; }
double StepContext::dt() const { return impl_->state.dt; }
int StepContext::iteration() const { return impl_->state.iteration; }
const std::filesystem::path& StepContext::output_dir() const { return impl_->state.output_dir; }
bool StepContext::is_height_field() const { return impl_->state.height_field; }
std::span<const int> StepContext::active_vertices() const { return impl_->state.active; }
std::optional<double> StepContext::clock_start() const { return impl_->state.clock_start; }

double StepContext::mesh_size() const {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->mesh_size) impl_->mesh_size = edge_length_stats(mesh()).mean;
  return *impl_->mesh_size;
}

const std::vector<double>& StepContext::face_areas() const {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->face_areas) {
    std::vector<double> areas(mesh().n_faces(), 0.0);
    for (auto f : mesh().faces()) areas[f.idx()] = face_area(mesh(), f);
    impl_->face_areas = std::move(areas);
  }
  return *impl_->face_areas;
}

const VectorField& StepContext::face_normals() const {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->face_normals) {
    VectorField normals(mesh().n_faces(), Vec3(0, 0, 0));
    for (auto f : mesh().faces()) normals[f.idx()] = face_normal(mesh(), f);
    impl_->face_normals = std::move(normals);
  }
  return *impl_->face_normals;
}

const VectorField& StepContext::vertex_normals() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->vertex_normals_locked();
}

const VectorField& StepContext::surface_normals() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->surface_normals_locked();
}

std::span<const int> StepContext::band_vertices() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->where_velocity_is_read();
}

const VectorField& StepContext::conormal() const {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->conormal) {
    // Area-weighted face gradients of d, projected on the vertex tangent plane, normalised.
    // |∇_S d| = 1 away from the cut locus; where the average cancels (ridges of d) n_Σ is 0.
    // In a band, only at the active vertices (d is a distance only there).
    auto unit = [](const Vec3& g) {
      const double length = g.norm();
      return length > 1e-12 ? g / length : Vec3(0, 0, 0);
    };
    VectorField n;
    const std::span<const int> active = impl_->state.active;
    const double width = impl_->state.distance_width;
    if (active.empty() && std::isfinite(width)) {
      // d banded: beyond the band and its ring every face is flat (±width), n_Σ is 0 there. The
      // band's vertices and their ring get the whole-surface values, bit for bit.
      const std::span<const int> where = impl_->where_velocity_is_read();
      n = bodyfit::vertex_gradients(mesh(), distance(), where);
      for (int v : where) n[v] = unit(n[v]);
    } else if (active.empty()) {
      n = bodyfit::vertex_gradients(mesh(), distance());
      for (auto& g : n) g = unit(g);
    } else {
      // The whole-surface values, bit for bit: a band then gives the same front as the whole surface.
      n = bodyfit::vertex_gradients(mesh(), distance(), active);
      for (int v : active) n[v] = unit(n[v]);
    }
    impl_->conormal = std::move(n);
  }
  return *impl_->conormal;
}

VectorField StepContext::face_gradients(const ScalarField& u) const { return bodyfit::face_gradients(mesh(), u); }
VectorField StepContext::vertex_gradients(const ScalarField& u) const { return bodyfit::vertex_gradients(mesh(), u); }

const Eigen::SparseMatrix<double>& StepContext::mass_matrix() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->mass_locked();
}

const Eigen::SparseMatrix<double>& StepContext::stiffness_matrix() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stiffness_locked();
}

const std::vector<double>& StepContext::lumped_mass() const {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->lumped_mass) impl_->lumped_mass = bodyfit::lumped_mass(mesh());
  return *impl_->lumped_mass;
}

ScalarField StepContext::divergence(const VectorField& field) const { return surface_divergence(mesh(), field); }

const ScalarField& StepContext::front_curvature() const {
  std::lock_guard lock(impl_->mutex);
  if (!impl_->front_curvature) impl_->front_curvature = level_set_curvature(mesh(), distance());
  return *impl_->front_curvature;
}

ScalarField StepContext::smooth(const ScalarField& f, double length) const {
  if (length == 0) return f;
  std::lock_guard lock(impl_->mutex);  // CHOLMOD's workspace is shared by the solves
  return impl_->smoother_locked(length).smooth(f);
}

VectorField StepContext::smooth(const VectorField& f, double length) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->smoother_locked(length).smooth(f);
}

}  // namespace bodyfit
