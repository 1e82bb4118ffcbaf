// The evolution loop as a step lifecycle (evolution.hpp): Evolution::run reads as the five steps.
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>

#include <bodyfit/band_advector.hpp>
#include "blocks.hpp"
#include "step_state.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

namespace bodyfit {
namespace {

/// The model's grids and values when the caller takes none.
class DroppedOutputs final : public ModelOutputs {
 public:
  void grid(std::string_view, const GridField&) override {}
  void value(std::string_view, double) override {}
};

class Stopwatch {
 public:
  double lap_ms() {
    auto now = std::chrono::steady_clock::now();
    double ms = std::chrono::duration<double, std::milli>(now - start_).count();
    start_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// What a step's cut changes in T^n, which is otherwise as the last remesh left it: G^n's boundary
/// (its vertices lose their interface tags), what the front swept (d^n and φ^{n+1} of opposite
/// signs: labels), and the new boundary (φ = 0: the cut's vertices, and those it snaps). Marked on
/// T^n's vertices in a property of the mesh before the cut, so that they follow its renumbering,
/// and asked by the remesh after it (RemeshOptions::changed); removed with this object.
class ChangedVertices {
 public:
  ChangedVertices(SurfaceMesh& mesh, const ScalarField& distance, const ScalarField& phi_next) : mesh_(mesh) {
    mesh_.add_property(changed_);
    const int nv = int(mesh_.n_vertices());
    const bool known = distance.size() == std::size_t(nv) && phi_next.size() == std::size_t(nv);
    for_each_index(nv, [&](int i) {
      const std::size_t v = std::size_t(i);
      mesh_.property(changed_, VertexHandle(i)) = !known || (distance[v] < 0) != (phi_next[v] < 0);
    });
    for (auto e : mesh_.edges())
      if (mesh_.interface(e))
        for (int side : {0, 1}) mesh_.property(changed_, mesh_.to_vertex_handle(mesh_.halfedge_handle(e, side))) = 1;
  }
  ~ChangedVertices() { mesh_.remove_property(changed_); }
  ChangedVertices(const ChangedVertices&) = delete;
  ChangedVertices& operator=(const ChangedVertices&) = delete;

  /// Vertices the cut adds start unmarked (the property's default): they lie on the new boundary.
  bool operator()(VertexHandle v) const { return mesh_.property(changed_, v) || mesh_.phi(v) == 0; }

 private:
  SurfaceMesh& mesh_;
  OpenMesh::VPropHandleT<char> changed_;
};

std::size_t count_inside(const SurfaceMesh& mesh) {
  std::size_t n = 0;
  for (auto f : mesh.faces()) n += mesh.inside(f);
  return n;
}

/// d of a state: the signed distance to G, or ∓∞ everywhere when G is the whole surface or empty.
/// Within options.narrow_band of Σ when finite, ±that width beyond (what a model can differentiate).
ScalarField distance_of(const SurfaceMesh& mesh, DistanceSolver& solver, const DistanceOptions& options) {
  const std::size_t inside = count_inside(mesh);
  if (!(inside > 0 && inside < mesh.n_faces())) return ScalarField(mesh.n_vertices(), inside ? -INFINITY : INFINITY);
  ScalarField d = solver.signed_distance_to_region(options);
  if (std::isfinite(options.narrow_band))
    for (double& value : d)
      if (std::isinf(value)) value = std::copysign(options.narrow_band, value);
  return d;
}

/// The model's field as the vector field V the advection takes (V = v·n_Σ for a normal speed),
/// written at the vertices `where` (all when empty) and checked there: finite vectors.
void velocity_into(const VelocityField& field, const StepContext& context, std::string_view model,
                   std::span<const int> where, VectorField& velocity) {
  const std::size_t n = context.mesh().n_vertices();
  const bool tangential = field.kind == VelocityField::Kind::Tangential;
  const std::size_t given = tangential ? field.vector.size() : field.normal_speed.size();
  if (given != n)
    throw PluginError(fmt::format("model '{}' failed in compute at iteration {}: {} {} for {} vertices", model,
                                  context.iteration(), given, tangential ? "velocities" : "normal speeds", n));
  const VectorField* conormal = tangential ? nullptr : &context.conormal();
  velocity.resize(n);
  auto set = [&](std::size_t i) {
    const Vec3 v = tangential ? field.vector[i] : field.normal_speed[i] * (*conormal)[i];
    // A NaN would pass through the advection and the cut silently and give a wrong region.
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw PluginError(fmt::format("model '{}' failed in compute at iteration {}: non-finite velocity at vertex {} "
                                    "({}, {}, {})",
                                    model, context.iteration(), i, v[0], v[1], v[2]));
    velocity[i] = v;
  };
  if (where.empty())
    for (std::size_t i = 0; i < n; ++i) set(i);
  else
    for (int i : where) set(std::size_t(i));
}

VectorField velocity_of(const VelocityField& field, const StepContext& context, std::string_view model) {
  VectorField velocity;
  velocity_into(field, context, model, {}, velocity);
  return velocity;
}

/// The vertices where |φ| ≤ width (sorted).
std::vector<int> within(const ScalarField& phi, double width) {
  std::vector<int> band;
  for (std::size_t i = 0; i < phi.size(); ++i)
    if (std::abs(phi[i]) <= width) band.push_back(int(i));
  return band;
}

/// The longest edge of a garbage-collected mesh (a parallel max: the same for any thread count).
double longest_edge(const SurfaceMesh& mesh) {
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, int(mesh.n_edges()), 16384), 0.0,
      [&](const tbb::blocked_range<int>& range, double longest) {
        for (int e = range.begin(); e != range.end(); ++e) longest = std::max(longest, edge_length(mesh, EdgeHandle(e)));
        return longest;
      },
      [](double a, double b) { return std::max(a, b); });
}

/// What step 2 (d, V, advection, sub-steps) hands to the cut.
struct LevelSetStep {
  ScalarField phi_next;           ///< φ^{n+1} on T^n
  /// d^n with the step's nuclei added (VelocityModel::nuclei), for drop_detached; empty: none.
  ScalarField nucleated;
  double done = 0;                ///< time advanced (the step, or less when G vanished within it)
  int substeps = 0;
  StageTimes ms;
};

/// What the CFL sub-steps of one step on T^n share (Evolution::front_step): where they work and
/// how far the front can go in one of them.
struct FrontSubsteps {
  bool in_band = true;            ///< near the front only (EvolutionOptions::narrow_band)
  bool compose = false;           ///< characteristics composed back to T^n's φ (compose_substeps)
  double traced_width = 0;        ///< the vertices traced: the front can reach them within a sub-step
  double width = 0;               ///< where the traces read d and V
  std::vector<int> band, traced;  ///< the vertices within width, and within traced_width, of the front
  std::vector<int> everything;    ///< composed whole-surface sub-steps: every vertex (where V is known)
  ScalarField next;               ///< φ at the end of the sub-step (in the band: the whole field)
};

class Evolution {
 public:
  Evolution(SurfaceMesh& mesh, VelocityModel& model, const EvolutionOptions& options, const RunState& start,
            const EvolutionHooks& hooks)
      : mesh_(mesh), model_(model), options_(options), hooks_(hooks), needs_(model.needs()),
        // A frozen V over CFL sub-steps transports φ on the whole surface (the whole-surface path).
        banded_(options.narrow_band && !needs_.whole_surface_distance &&
                !(needs_.freeze_velocity && options.max_cfl > 0)),
        n_(start.iteration), t_(start.time), dt_(start.dt > 0 ? start.dt : options.dt) {}

  EvolutionResult run() {
    try {
      // CFL sub-steps know their band before V does (front_band_width): d^0 measured in it, as
      // every later d^n is, and not on the whole surface (where the first V would be asked for).
      if (banded_ && options_.max_cfl > 0) {
        longest_edge_ = longest_edge(mesh_);
        band_width_ = next_band_width(front_band_width() + 2 * longest_edge_);
      }
      measure_distance();
      while (!should_stop()) advance();
      return finish();
    } catch (...) {
      failed();
      throw;
    }
  }

 private:
  // ---- 1. decide whether to stop -------------------------------------------------------------
  bool should_stop() {
    if (stopped_) return true;
    const std::size_t inside = count_inside(mesh_);
    if (!(options_.final_time - t_ > tiny()))
      stop(StopReason::FinalTime, fmt::format("final time {} reached", options_.final_time));
    else if (options_.max_iterations >= 0 && n_ >= options_.max_iterations)
      stop(StopReason::Iterations, fmt::format("iteration count {} reached", options_.max_iterations));
    else if (hooks_.stop && hooks_.stop->load())
      stop(StopReason::Interrupted, fmt::format("interrupted after iteration {} (t = {})", n_, t_));
    else if (inside == 0)
      stop(StopReason::Vanished, fmt::format("G vanished at iteration {} (t = {})", n_, t_));
    else if (inside == mesh_.n_faces())
      stop(StopReason::Filled, fmt::format("G fills the whole surface at iteration {} (t = {})", n_, t_));
    return stopped_;
  }

  /// One step n → n + 1: attempts until the model accepts a candidate (or the retries run out).
  void advance() {
    double step = dt_;
    if (options_.final_time - t_ < dt_ + tiny()) step = options_.final_time - t_;  // land exactly on T
    for (const auto& region : options_.additions)  // and on the time a region joins G
      if (region.time - t_ > tiny() && region.time - t_ < step - tiny()) step = region.time - t_;
    // T^n and d^n are kept only for a model that may reject (a copy of the mesh).
    std::optional<SurfaceMesh> kept_mesh;
    ScalarField kept_distance;
    if (needs_.may_reject) kept_mesh = mesh_, kept_distance = distance_, kept_width_ = distance_width_;
    for (int attempt = 0;; ++attempt) {
      const double dt = step / std::ldexp(1.0, attempt);
      LevelSetStep level_set = level_set_step(dt, attempt);  // 2.
      add_nuclei(level_set, attempt);
      cut_and_remesh(level_set);                             // 3. T^n is now the candidate
      Review review = review_or_restore(level_set, attempt, kept_mesh, kept_distance);  // 4.
      if (review.accepted()) {                               // 5.
        accept(level_set, std::move(review), step, attempt);
        return;
      }
      if (!kept_mesh)
        throw PluginError(fmt::format("model '{}' failed in review at iteration {}: rejected a step but did not "
                                      "declare ModelNeeds::may_reject",
                                      model_.name(), n_ + 1));
      mesh_ = *kept_mesh;  // restore T^n exactly
      mean_edge_ = NAN;
      candidate_ = false;
      distance_ = kept_distance;
      distance_width_ = kept_width_;
      solver_.reset();  // built on the candidate
      if (hooks_.log)
        spdlog::info("n={} step of dt={:.5g} rejected by model '{}': {}{}", n_ + 1, dt, model_.name(), review.reason,
                     review.stop ? std::string("; the model stops the run")
                     : attempt < options_.max_rejections ? fmt::format("; retrying with dt={:.5g}", dt / 2)
                                                          : std::string());
      rejections_ += 1;
      if (review.stop) {
        stop(StopReason::ModelStop, review.reason.empty() ? "the model stopped the run" : review.reason);
        return;
      }
      if (attempt >= options_.max_rejections) {
        stop(StopReason::Rejected,
             fmt::format("step {} (t = {}) rejected {} times by model '{}' (last: {}); T^{} is the final state", n_ + 1,
                         t_, attempt + 1, model_.name(), review.reason, n_));
        return;
      }
    }
  }

  // ---- 2. d and V, advection (CFL sub-steps on T^n) -------------------------------------------
  LevelSetStep level_set_step(double dt, int attempt) {
    if (options_.max_cfl > 0 && !needs_.freeze_velocity) return front_step(dt, attempt);
    // One advection over the step (or, for a frozen V, CFL sub-steps transporting φ with it).
    LevelSetStep step;
    Stopwatch clock;
    VectorField velocity = first_velocity(step, dt, attempt, clock, nullptr, banded_ && !(options_.max_cfl > 0));
    if (banded_ && !(options_.max_cfl > 0)) {
      band_step(step, velocity, dt, attempt);
      step.ms.advect += clock.lap_ms();
      return step;
    }
    Advector advector(mesh_);
    ScalarField phi = distance_;
    while (step.done < dt) {
      const double remaining = dt - step.done;
      const double sub = substep_length(velocity, {}, remaining, step.substeps);
      ScalarField next = advect_substep(advector, phi, velocity, sub, remaining, dt, attempt, step);
      step.ms.advect += clock.lap_ms();
      phi = std::move(next);
      // G vanished or fills S within the step: nothing left to move.
      const auto [lowest, highest] = std::minmax_element(phi.begin(), phi.end());
      if (step.done < dt && (*lowest >= 0 || *highest < 0)) break;
    }
    step.phi_next = std::move(phi);
    return step;
  }

  /// CFL sub-steps with V recomputed on the moved front: each redistances φ, asks the model for V
  /// and advects. With options_.narrow_band only near the front (EvolutionOptions::narrow_band),
  /// else on the whole surface; max|V| is over the band in both.
  LevelSetStep front_step(double dt, int attempt) {
    LevelSetStep step;
    Stopwatch clock;
    if (!solver_) solver_.emplace(mesh_);  // T^n's flat arrays, for every sub-step
    if (banded_) {  // d^n must hold the sub-steps' band (front_substeps), and a ring for V there
      const double need = front_band_width() + 2 * longest_edge_;
      ensure_band(need);
      band_width_ = next_band_width(need);
    }
    // In a band (without composition) the sub-steps' Advector is built on the band's faces only.
    std::optional<Advector> whole;
    if (!options_.narrow_band || options_.compose_substeps) whole.emplace(mesh_);
    BandAdvector band_advector(mesh_);
    StepGeometry geometry;
    ScalarField phi = distance_;
    FrontSubsteps f = front_substeps(phi, whole ? &*whole : nullptr);
    step.ms.distance += clock.lap_ms();
    VectorField velocity;
    while (step.done < dt) {
      const double remaining = dt - step.done;
      if (step.substeps > 0) {  // φ: the advected one, redistanced around its zero set
        redistance_front(f, phi);
        step.ms.distance += clock.lap_ms();
        if (f.band.empty()) break;  // G vanished or fills S within the step
      }
      const std::span<const int> active = f.in_band ? std::span<const int>(f.band) : std::span<const int>();
      if (step.substeps == 0) {
        const int version = distance_version_;
        velocity = first_velocity(step, dt, attempt, clock, &geometry);
        if (version != distance_version_) {  // d^n measured again on the whole surface
          phi = distance_;
          f = front_substeps(phi, whole ? &*whole : nullptr);
        }
      } else {
        const StepContext context = context_for(mesh_, phi, n_, t_ + step.done, remaining, active, &geometry);
        const VelocityField field = model_.compute(context);
        velocity_into(field, context, model_.name(), active, velocity);
        step.ms.velocity += clock.lap_ms();
      }
      // The vertices the front can reach within a sub-step: traced, and their speed sizes it (a
      // characteristic from further away must cross them, which takes longer than the sub-step).
      f.traced.clear();
      for (int v : f.band)
        if (std::abs(phi[v]) <= f.traced_width) f.traced.push_back(v);
      const double sub = substep_length(velocity, f.traced, remaining, step.substeps);
      advect_front(f, whole ? &*whole : nullptr, band_advector, phi, velocity, sub, remaining, dt, attempt, step);
      step.ms.advect += clock.lap_ms();
    }
    step.phi_next = std::move(phi);
    return step;
  }

  /// The sub-steps' widths and first band on T^n (and the composition's start at φ^n).
  FrontSubsteps front_substeps(const ScalarField& phi, Advector* whole) const {
    FrontSubsteps f;
    f.in_band = options_.narrow_band;
    f.compose = options_.compose_substeps;
    const double cap = options_.max_cfl * cfl_length();
    // The front cannot reach further within a sub-step, and the cut reads φ two rings beyond the
    // vertices of its crossed edges (DiscretizeOptions::fitted_slopes): 3 edges, not 2.
    f.traced_width = cap + 3 * longest_edge_;
    f.width = front_band_width();
    f.band = within(phi, f.width);
    if (f.in_band) f.next = phi;
    if (f.compose) {
      whole->start_composition(phi);
      if (!f.in_band) {
        f.everything.resize(mesh_.n_vertices());
        std::iota(f.everything.begin(), f.everything.end(), 0);
      }
    }
    return f;
  }

  /// φ redistanced around its zero set: in the band (the vertices leaving it keep ±width), or on
  /// the whole surface.
  void redistance_front(FrontSubsteps& f, ScalarField& phi) {
    DistanceOptions redistancing = options_.distance;
    redistancing.keep_crossings = options_.keep_crossings;
    if (!f.in_band) {
      phi = solver_->signed_distance(phi, redistancing);
      f.band = within(phi, f.width);
      return;
    }
    std::vector<int> moved = solver_->redistance(phi, f.width, f.traced, nullptr, redistancing);
    // Leaving the band: |φ| ≥ width with its sign, so that φ stays a distance clamped there.
    for (int v : f.band)
      if (!std::binary_search(moved.begin(), moved.end(), v)) phi[v] = f.next[v] = std::copysign(f.width, phi[v]);
    for (int v : moved) f.next[v] = phi[v];
    f.band = std::move(moved);
  }

  /// One sub-step of `sub` advecting φ: the traced vertices in the band; or on the whole surface,
  /// composed back to T^n or not.
  void advect_front(FrontSubsteps& f, Advector* whole, BandAdvector& band_advector, ScalarField& phi,
                    const VectorField& velocity, double sub, double remaining, double dt, int attempt,
                    LevelSetStep& step) {
    if (!f.in_band && !f.compose) {
      phi = advect_substep(*whole, phi, velocity, sub, remaining, dt, attempt, step);
      return;
    }
    const AdvectionOptions& advection = options_.advection;
    AdvectionReport report;
    if (!f.in_band) f.next = phi;  // as in the band: only the vertices the front can reach are traced
    const std::vector<int>& known = f.in_band ? f.band : f.everything;  // where V is known
    // Built around the band as far as two more sub-steps may take it (rings counted as 3/4 of a mean
    // edge), built again when the band gets beyond it.
    auto covering = [&]() -> Advector& {
      const double rings = std::ceil((f.width + 2 * options_.max_cfl * cfl_length()) / (0.75 * cfl_length())) + 2;
      return band_advector.covering(known, int(std::min(rings, double(mesh_.n_vertices()))));
    };
    Advector& advector = whole ? *whole : covering();
    if (f.compose)
      advector.advect_band_composed(phi, velocity, sub, f.traced, known, f.next, advection, &report);
    else
      advector.advect_band(phi, velocity, sub, f.traced, known, f.next, advection, &report);
    check_report(report);
    if (f.in_band) {
      model_.end_step(StepOutcome{mesh_, phi, f.next, t_ + step.done, sub, attempt, f.traced});
      for (int v : f.traced) phi[v] = f.next[v];
    } else {
      model_.end_step(StepOutcome{mesh_, phi, f.next, t_ + step.done, sub, attempt});
      std::swap(phi, f.next);
    }
    advance_substep(step, sub, remaining, dt);
  }

  /// V^n on T^n with d^n, over the whole surface (the state's outputs show it); a retried step
  /// reuses it (T^n and d^n are those of the first attempt). With `check_reach` (one advection
  /// over Δt in a band), d^n's band is widened, and V asked for again, until it holds what the
  /// step's characteristics reach (band_need).
  VectorField first_velocity(LevelSetStep& step, double dt, int attempt, Stopwatch& clock,
                             StepGeometry* geometry = nullptr, bool check_reach = false) {
    while (attempt == 0) {
      const StepContext context = context_for(mesh_, distance_, n_, t_, dt, {}, geometry);
      state_field_ = model_.compute(context);
      state_velocity_ = velocity_of(state_field_, context, model_.name());
      step.ms.velocity += clock.lap_ms();
      if (banded_ && whole_surface_used_) {  // V^n couples d everywhere: banded, it must be asked again
        const bool again = std::isfinite(distance_width_);
        whole_surface();
        step.ms.distance += clock.lap_ms();
        if (again) continue;
      }
      if (!check_reach) break;
      const double need = band_need(step_reach(state_velocity_, dt));
      if (need <= distance_width_) break;
      ensure_band(need);
      step.ms.distance += clock.lap_ms();
    }
    step.ms.velocity += clock.lap_ms();
    if (attempt == 0 && hooks_.on_state) {  // outputs show the state T^n with d^n and V^n
      hooks_.on_state(StateView{mesh_, n_, t_, distance_, &state_velocity_, &state_field_, false});
      step.ms.output += clock.lap_ms();
    }
    return state_velocity_;
  }

  /// One advection over the step in d^n's band: the vertices the front can reach are traced
  /// (reach + 3 edges: the cut reads φ two rings beyond its crossed edges' vertices), the others
  /// keep d^n, whose sign is all the cut reads there.
  void band_step(LevelSetStep& step, const VectorField& velocity, double dt, int attempt) {
    const double reach = step_reach(velocity, dt);
    const std::vector<int> traced = within(distance_, reach + 3 * longest_edge_);
    const std::vector<int> known = within(distance_, 2 * reach + 5 * longest_edge_);
    Advector advector(mesh_, faces_around(mesh_, known));  // the walk's arrays for the band only
    ScalarField next = distance_;
    AdvectionReport report;
    advector.advect_band(distance_, velocity, dt, traced, known, next, options_.advection, &report);
    check_report(report);
    if (report.outside_band > 0)  // band_need makes this impossible; a wrong front is never returned
      throw NumericalError(fmt::format("step {} (t = {:.6g}): {} characteristics left the band of d^n (width {:.6g}, "
                                       "reach {:.6g}); the step is not taken: set [time] narrow_band = false",
                                       n_ + 1, t_, report.outside_band, distance_width_, reach));
    model_.end_step(StepOutcome{mesh_, distance_, next, t_, dt, attempt, traced});
    advance_substep(step, dt, dt, dt);
    step.phi_next = std::move(next);
    band_width_ = next_band_width(band_need(reach));
  }

  /// How far the characteristics of a step of `dt` go: max |V|·dt over the vertices where V is
  /// known (d^n a distance there and one ring further: the conormal reads the ring).
  double step_reach(const VectorField& velocity, double dt) const {
    const double trusted = distance_width_ - 2 * longest_edge_;
    double vmax = 0;
    for (std::size_t i = 0; i < velocity.size(); ++i)
      if (std::abs(distance_[i]) <= trusted) vmax = std::max(vmax, velocity[i].norm());
    return vmax * dt;
  }

  /// The width of d^n a step of this reach reads: its traced vertices (reach + 3 edges), the faces
  /// their characteristics cross (reach more, and a face), the gradients at those faces' corners
  /// (a ring) and the conormal there (one more).
  double band_need(double reach) const { return 2 * reach + 6 * longest_edge_; }
  /// The width of the sub-steps' band (FrontSubsteps::width).
  double front_band_width() const { return 2 * options_.max_cfl * cfl_length() + 5 * longest_edge_; }

  /// The width the next state's d is measured with: half as much again as this step needed, so
  /// that a front speeding up does not make every step widen it (and no wider than [distance]
  /// narrow_band, when the case sets it).
  double next_band_width(double need) const {
    return std::max(need, std::min(1.5 * need, options_.distance.narrow_band));
  }

  /// The model couples every vertex (StepContext::whole_surface_used): d on the whole surface from
  /// now on, d^n measured again.
  void whole_surface() {
    if (hooks_.log)
      spdlog::info("n={}: model '{}' uses mass, stiffness or smoothing on the surface: d is measured on the whole "
                   "surface from now on (ModelNeeds::whole_surface_distance says so from the start)",
                   n_, model_.name());
    banded_ = false;
    band_width_ = INFINITY;
    if (std::isfinite(distance_width_)) measure_distance(/*same_mesh=*/true);
  }

  /// d^n measured again when its band is narrower than `need` (a front faster than the last step's):
  /// the band is detected too narrow and widened, never used as it is.
  void ensure_band(double need) {
    if (need <= distance_width_) return;
    if (need > options_.distance.narrow_band)
      throw InputError(fmt::format(
          "step {} (t = {:.6g}): the step reads d up to {:.6g} from the front (twice its reach and 6 edges), beyond "
          "[distance] narrow_band = {:.6g}: widen it, or leave it out (the driver sizes its band to each step)",
          n_ + 1, t_, need, options_.distance.narrow_band));
    spdlog::debug("n={}: d's band widened from {:.6g} to {:.6g}", n_, distance_width_, next_band_width(need));
    band_width_ = next_band_width(need);
    measure_distance(/*same_mesh=*/true);
  }

  /// One whole-surface advection sub-step: φ at its end.
  ScalarField advect_substep(Advector& advector, const ScalarField& phi, const VectorField& velocity, double sub,
                             double remaining, double dt, int attempt, LevelSetStep& step) {
    AdvectionReport report;
    ScalarField next = advector.advect(phi, velocity, sub, options_.advection, &report);
    check_report(report);
    model_.end_step(StepOutcome{mesh_, phi, next, t_ + step.done, sub, attempt});
    advance_substep(step, sub, remaining, dt);
    return next;
  }

  void advance_substep(LevelSetStep& step, double sub, double remaining, double dt) const {
    ++step.substeps;
    step.done = sub == remaining ? dt : step.done + sub;
  }

  /// A lost characteristic leaves its vertex with a value from the middle of its path: a wrong φ,
  /// so the step is not taken (everything up to T^n is in the last checkpoint).
  void check_report(const AdvectionReport& report) const {
    if (report.lost > 0)
      throw NumericalError(fmt::format(
          "step {} (t = {:.6g}): {} of {} characteristics were lost in the advection (a walk stalled or overflowed, "
          "or a trace reached its bound of sub-steps); the step is not taken: shorten [time] dt or set max_cfl",
          n_ + 1, t_, report.lost, report.traced));
  }

  /// Equal sub-steps over what remains of the step, each moving no point of `band` (all when
  /// empty) by more than max_cfl·h.
  double substep_length(const VectorField& velocity, std::span<const int> band, double remaining, int taken) const {
    if (!(options_.max_cfl > 0)) return remaining;
    double vmax = 0;
    if (band.empty())
      for (const Vec3& v : velocity) vmax = std::max(vmax, v.norm());
    else
      for (int i : band) vmax = std::max(vmax, velocity[i].norm());
    if (!std::isfinite(vmax))
      throw PluginError(fmt::format("model '{}' failed in compute at iteration {}: non-finite velocity (max_cfl cannot "
                                    "size the sub-steps)",
                                    model_.name(), n_));
    const double ratio = vmax * remaining / (options_.max_cfl * cfl_length());
    const double needed = taken + std::ceil(ratio - 1e-9);
    if (options_.max_substeps > 0 && needed > double(options_.max_substeps))
      throw InputError(fmt::format(
          "step {} (t = {:.6g}, dt = {:.6g}) needs {:.3g} CFL sub-steps (max |V| {:.3g} over {:.6g} of time, max_cfl "
          "{:.3g} × h {:.3g}), above the limit of {}: shorten [time] dt (or cfl), or raise [time] max_substeps (0: no "
          "limit)",
          n_ + 1, t_, options_.dt, needed, vmax, remaining, options_.max_cfl, cfl_length(), options_.max_substeps));
    return ratio > 1 + 1e-9 ? remaining / std::ceil(ratio - 1e-9) : remaining;  // 3.0000000000000004 is 3
  }

  /// h of the CFL condition: [time] cfl_length, or T^n's mean edge length (a pass over its edges,
  /// taken once per mesh: every sub-step asks for it).
  double cfl_length() const {
    if (options_.cfl_length > 0) return options_.cfl_length;
    if (std::isnan(mean_edge_)) mean_edge_ = mean_edge_length(mesh_);
    return mean_edge_;
  }

  /// The model's new components of G: φ^{n+1} ← min(φ^{n+1}, ψ) on T^n, and the same for d^n where
  /// drop_detached looks for what G^{n+1} grew from (a nucleus is not a detached part).
  void add_nuclei(LevelSetStep& step, int attempt) {
    Stopwatch clock;
    const StepContext context = context_for(mesh_, distance_, n_, t_, step.done);
    const std::vector<Nucleus> nuclei = model_.nuclei(context, attempt);
    if (nuclei.empty()) return;
    step.nucleated = distance_;
    for (const Nucleus& nucleus : nuclei) {
      const ScalarField psi = nucleus_level_set(mesh_, nucleus);
      for (std::size_t v = 0; v < psi.size(); ++v) {
        step.phi_next[v] = std::min(step.phi_next[v], psi[v]);
        step.nucleated[v] = std::min(step.nucleated[v], psi[v]);
      }
    }
    if (hooks_.log)
      spdlog::info("n={} t={:.5g}: model '{}' adds {} new component(s) of G", n_, t_, model_.name(), nuclei.size());
    step.ms.velocity += clock.lap_ms();
  }

  // ---- 3. cut and remesh: the candidate T^{n+1} -------------------------------------------------
  void cut_and_remesh(LevelSetStep& step) {
    candidate_ = true;  // from here on the mesh is no longer T^n
    solver_.reset();  // T^n's, and memory the remesh can use
    Stopwatch clock;
    DiscretizeOptions cut = options_.discretize;
    if (cut.drop_detached)  // d^n on T^n: G^{n+1} grows from G^n (and the step's nuclei)
      cut.grown_from = step.nucleated.empty() ? std::span<const double>(distance_) : std::span<const double>(step.nucleated);
    // The remesh looks for work only where the cut changed T^n, unless the model computes on the
    // whole mesh (ModelNeeds::remesh_everywhere).
    std::optional<ChangedVertices> changed;
    if (!needs_.remesh_everywhere) changed.emplace(mesh_, distance_, step.phi_next);
    const DiscretizeReport report = discretize(mesh_, step.phi_next, cut);
    if (report.removed_detached > 0)
      spdlog::debug("n={}: {} part(s) of G detached from G^n given to the outside", n_ + 1, report.removed_detached);
    step.ms.discretize += clock.lap_ms();
    RemeshOptions remeshing = options_.remesh;
    if (changed) remeshing.changed = [&](VertexHandle v) { return (*changed)(v); };
    remesh(mesh_, remeshing);
    if (options_.canonical_order) canonicalize(mesh_);
    step.ms.remesh += clock.lap_ms();
    measure_distance();  // d^{n+1}: the review's and the next step's
    step.ms.distance += clock.lap_ms();
  }

  // ---- 4. the model's review ---------------------------------------------------------------------
  /// The review; when it throws, T^n is restored if it was kept (the caller may then save it).
  Review review_or_restore(LevelSetStep& step, int attempt, const std::optional<SurfaceMesh>& kept_mesh,
                           const ScalarField& kept_distance) {
    try {
      return review_candidate(step, attempt);
    } catch (...) {
      if (kept_mesh)
        mesh_ = *kept_mesh, distance_ = kept_distance, distance_width_ = kept_width_, mean_edge_ = NAN, candidate_ = false;
      throw;
    }
  }

  Review review_candidate(LevelSetStep& step, int attempt) {
    Stopwatch clock;
    const StepContext candidate = context_for(mesh_, distance_, n_ + 1, t_ + step.done, step.done);
    Review review = model_.review(candidate, attempt);
    step.ms.review += clock.lap_ms();
    if (!(std::isfinite(review.next_dt) && review.next_dt >= 0))  // inf would end the run in one step
      throw PluginError(fmt::format("model '{}' failed in review at iteration {}: next Δt {} (expected a finite value ≥ 0)",
                                    model_.name(), n_ + 1, review.next_dt));
    return review;
  }

  // ---- 5. accept: record, outputs, checkpoint ----------------------------------------------------
  void accept(const LevelSetStep& step, Review review, double nominal_dt, int attempt) {
    candidate_ = false;  // T^{n+1} is the state now
    ++n_;
    const double before = t_;
    t_ += step.done;
    StageTimes ms = step.ms;
    add_scheduled_regions(before, ms);
    if (review.next_dt > 0) dt_ = review.next_dt;
    Stopwatch clock;
    IterationRecord record = measure_state(mesh_, n_, t_);
    ms.output += clock.lap_ms();  // the record's measures are part of what each state costs
    record.dt = nominal_dt / std::ldexp(1.0, attempt);
    record.ms = ms;
    record.substeps = step.substeps;
    record.rejections = rejections_;
    rejections_ = 0;
    record.metrics = state_field_.metrics;
    for (auto& m : review.metrics) record.metrics.push_back(std::move(m));
    if (hooks_.on_iteration) hooks_.on_iteration(mesh_, record, RunState{n_, t_, dt_});
    record.ms.output += clock.lap_ms();
    result_.records.push_back(std::move(record));
    if (review.stop) stop(StopReason::ModelStop, review.reason.empty() ? "the model stopped the run" : review.reason);
  }

  /// The regions whose time came within (before, t_] joined to the accepted state: φ = min(d, ψ)
  /// cut into it and remeshed (EvolutionOptions::additions).
  void add_scheduled_regions(double before, StageTimes& ms) {
    std::vector<const ScheduledRegion*> due;
    for (const auto& region : options_.additions)
      if (region.time - before > tiny() && region.time - t_ <= tiny()) due.push_back(&region);
    if (due.empty()) return;
    Stopwatch clock;
    ScalarField phi = distance_;
    for (auto v : mesh_.vertices())
      for (const ScheduledRegion* region : due) phi[v.idx()] = std::min(phi[v.idx()], region->level_set(mesh_.point(v)));
    model_.end_step(StepOutcome{mesh_, distance_, phi, t_, 0.0, 0});
    ms.velocity += clock.lap_ms();
    candidate_ = true;  // until remeshed, the mesh is neither T^{n+1} nor its union
    discretize(mesh_, phi, options_.discretize);
    ms.discretize += clock.lap_ms();
    remesh(mesh_, options_.remesh);
    if (options_.canonical_order) canonicalize(mesh_);
    ms.remesh += clock.lap_ms();
    measure_distance();
    ms.distance += clock.lap_ms();
    candidate_ = false;
    if (hooks_.log) spdlog::info("n={} t={:.5g}: {} region(s) joined G", n_, t_, due.size());
  }

  EvolutionResult finish() {
    // The final state's d on the whole surface (final.sol, the outputs, the model's finish): once.
    if (banded_ && distance_width_ < options_.distance.narrow_band) {
      banded_ = false;
      measure_distance(/*same_mesh=*/true);
    }
    solver_.reset();
    result_.iteration = n_;
    result_.time = t_;
    result_.final_distance = distance_;
    if (hooks_.on_state) {
      // The final state's V and model fields, for its outputs (one more compute, no advection).
      VectorField velocity;
      std::optional<VelocityField> field;
      const std::size_t inside = count_inside(mesh_);
      if (inside > 0 && inside < mesh_.n_faces()) {
        const StepContext context = context_for(mesh_, distance_, n_, t_, dt_);
        field = model_.compute(context);
        velocity = velocity_of(*field, context, model_.name());
      }
      hooks_.on_state(StateView{mesh_, n_, t_, distance_, field ? &velocity : nullptr, field ? &*field : nullptr, true});
    }
    if (hooks_.on_end) hooks_.on_end(mesh_, result_);  // before finish(): a failing finish() loses nothing
    const StepContext final_state = context_for(mesh_, distance_, n_, t_, dt_);
    DroppedOutputs dropped;
    model_.finish(final_state, hooks_.outputs ? *hooks_.outputs : dropped);
    return std::move(result_);
  }

  /// An exception is leaving the loop: while the mesh is still the state n_, the caller may save it.
  void failed() const {
    if (candidate_ || !hooks_.on_failure) return;
    try {
      hooks_.on_failure(mesh_, RunState{n_, t_, dt_});
    } catch (const std::exception& e) {
      spdlog::error("while saving the last completed iteration after a failure: {}", e.what());
    }
  }

  // ---- helpers ---------------------------------------------------------------------------------
  /// d of the current mesh, in a band of band_width_ when banded_; its solver is kept for the
  /// CFL sub-steps of the next step (same mesh).
  void measure_distance(bool same_mesh = false) {
    if (!same_mesh || !solver_) solver_.emplace(mesh_);
    if (!same_mesh) longest_edge_ = longest_edge(mesh_), mean_edge_ = NAN;
    DistanceOptions options = options_.distance;
    if (banded_) options.narrow_band = std::min(options.narrow_band, band_width_);
    distance_ = distance_of(mesh_, *solver_, options);
    distance_width_ = options.narrow_band;
    ++distance_version_;
    // Only CFL sub-steps redistance on this mesh again: otherwise its arrays (about the mesh's own
    // size) are not held through the step.
    if (!(options_.max_cfl > 0)) solver_.reset();
  }
  StepContext context_for(const SurfaceMesh& mesh, const ScalarField& d, int iteration, double time, double dt,
                          std::span<const int> active = {}, StepGeometry* geometry = nullptr) {
    return make_step_context(StepState{.mesh = &mesh,
                                       .distance = &d,
                                       // distance_'s band (a sub-step's φ is redistanced in its own)
                                       .distance_width = &d == &distance_ ? distance_width_ : INFINITY,
                                       .time = time,
                                       .dt = dt,
                                       .iteration = iteration,
                                       .output_dir = options_.output_dir,
                                       .height_field = options_.height_field,
                                       .clock_start = options_.clock_start,
                                       .active = active,
                                       .geometry = geometry,
                                       .surface = options_.remesh.reference.get(),
                                       .whole_surface_used = &whole_surface_used_});
  }
  void stop(StopReason reason, std::string message) {
    stopped_ = true;
    result_.reason = reason;
    result_.message = std::move(message);
  }
  double tiny() const { return 1e-9 * options_.dt; }
  SurfaceMesh& mesh_;
  VelocityModel& model_;
  const EvolutionOptions& options_;
  const EvolutionHooks& hooks_;
  const ModelNeeds needs_;
  /// d^n and the advection in a band of the front (narrow_band); off for good once the model asks
  /// for an operator coupling every vertex (whole_surface_used_, raised by its StepContext).
  bool banded_;
  bool whole_surface_used_ = false;
  int distance_version_ = 0;    ///< counts measure_distance (a sub-step set-up made on an older d is stale)
  int n_;
  double t_;
  double dt_;                   ///< Δt of the next step (the case's, or the model's latest)
  ScalarField distance_;        ///< d of the current state (or of the candidate, in steps 3-5)
  /// d's band: distance_ is exact within distance_width_ of Σ, ±it beyond (∞: the whole surface);
  /// band_width_ is what the next measure uses (∞ until a step has sized it).
  double distance_width_ = INFINITY, band_width_ = INFINITY, kept_width_ = INFINITY;
  double longest_edge_ = 0;     ///< of the current mesh
  mutable double mean_edge_ = NAN;  ///< of the current mesh, once asked for (cfl_length)
  std::optional<DistanceSolver> solver_;  ///< on the current mesh (distance_'s, then the sub-steps')
  VelocityField state_field_;   ///< the model's answer on T^n (first sub-step of the first attempt)
  VectorField state_velocity_;  ///< V^n
  int rejections_ = 0;          ///< of the current step
  bool candidate_ = false;      ///< mesh_ is a candidate T^{n+1} (cut or remeshed, not yet accepted)
  bool stopped_ = false;
  EvolutionResult result_;
};

}  // namespace

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::FinalTime: return "final time reached";
    case StopReason::Iterations: return "iteration count reached";
    case StopReason::Vanished: return "the region G vanished";
    case StopReason::Filled: return "the region G fills the whole surface";
    case StopReason::Interrupted: return "interrupted";
    case StopReason::ModelStop: return "stopped by the model";
    case StopReason::Rejected: return "step rejected too many times";
  }
  return "?";
}

IterationRecord measure_state(const SurfaceMesh& mesh, int iteration, double time) {
  IterationRecord r;
  r.iteration = iteration;
  r.time = time;
  r.area = region_area(mesh, kInside);
  r.interface_length = interface_length(mesh);
  r.components = region_components(mesh, kInside);
  auto q = quality_stats(mesh);
  r.min_quality = q.min;
  r.mean_quality = q.mean;
  r.vertices = mesh.n_vertices();
  r.faces = mesh.n_faces();
  return r;
}

void mesh_initial_region(SurfaceMesh& surface, const ScalarField& phi, const DiscretizeOptions& discretize_options,
                         const RemeshOptions& remesh_options) {
  if (phi.size() != surface.n_vertices())
    throw InputError(fmt::format("initial level set: {} values for {} vertices", phi.size(), surface.n_vertices()));
  bool negative = false, positive = false;
  for (double v : phi) (v < 0 ? negative : positive) = true;
  if (!negative) throw InputError("initial region: the level set is ≥ 0 everywhere (G(0) is empty)");
  if (!positive) throw InputError("initial region: the level set is < 0 everywhere (G(0) is the whole surface)");
  discretize(surface, phi, discretize_options);
  remesh(surface, remesh_options);
}

EvolutionResult evolve(SurfaceMesh& mesh, VelocityModel& model, const EvolutionOptions& options, const RunState& start,
                       const EvolutionHooks& hooks) {
  if (!(options.dt > 0)) throw InputError(fmt::format("evolution: the time step must be > 0 (got {})", options.dt));
  if (!mesh.has_regions()) throw InputError("evolution: the mesh has no face labelled inside (G is empty)");
  mesh.garbage_collection();
  if (options.canonical_order) canonicalize(mesh);
  return Evolution(mesh, model, options, start, hooks).run();
}

}  // namespace bodyfit
