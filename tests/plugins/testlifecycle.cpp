// A test model for the step lifecycle: constant normal speed, and on request it rejects the first
// candidate of every k-th step, stops the run at an iteration, and drives Δt (grown by a factor
// after every accepted step: state a resume must restore). It also checks that T^n is restored
// exactly before a retry (the arrays seen by end_step on attempt 0 and on the retries). A model stuck in
// compute: with `hang_file`, compute() waits while that file exists (a signal's escape is tested
// on it).
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <thread>

namespace {

using namespace bodyfit;

/// The connectivity arrays and points of a mesh, flattened (to compare two states exactly).
std::vector<double> arrays_of(const SurfaceMesh& mesh) {
  std::vector<double> out;
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    out.insert(out.end(), {p[0], p[1], p[2], mesh.phi(v), double(mesh.halfedge_handle(v).idx())});
  }
  for (auto h : mesh.halfedges())
    out.insert(out.end(), {double(mesh.to_vertex_handle(h).idx()), double(mesh.next_halfedge_handle(h).idx()),
                           double(mesh.face_handle(h).idx())});
  for (auto e : mesh.edges()) out.push_back(mesh.interface(e));
  for (auto f : mesh.faces()) out.push_back(mesh.region(f));
  return out;
}

class LifecycleModel final : public VelocityModel {
 public:
  std::string_view name() const override { return "testlifecycle"; }
  std::vector<ParameterDecl> parameters() const override {
    return {ParameterDecl::number("speed", "", "normal speed").fallback(1.0),
            ParameterDecl::integer("reject_every", "", "reject the first attempt of every k-th step (0: never)")
                .fallback(0)
                .at_least(0),
            ParameterDecl::integer("stop_at", "", "stop the run at this iteration (-1: never)").fallback(-1),
            ParameterDecl::number("grow_dt", "", "next Δt = this × Δt (0: the driver's)").fallback(0.0).at_least(0),
            ParameterDecl::boolean("freeze", "needs().freeze_velocity").fallback(false),
            ParameterDecl::integer("nan_at_vertex", "", "a NaN speed at this vertex (-1: none)").fallback(-1).at_least(-1),
            ParameterDecl::string("hang_file", "compute() waits while this file exists (\"\": never)").fallback("")};
  }
  void configure(Parameters& p) override {
    speed_ = p.number("speed");
    reject_every_ = p.integer("reject_every");
    stop_at_ = p.integer("stop_at");
    grow_dt_ = p.number("grow_dt");
    freeze_ = p.boolean("freeze");
    nan_at_ = p.integer("nan_at_vertex");
    hang_file_ = p.string("hang_file");
  }
  ModelNeeds needs() const override { return {.may_reject = reject_every_ > 0, .freeze_velocity = freeze_}; }

  VelocityField compute(const StepContext& context) override {
    ++computes_;
    while (!hang_file_.empty() && context.iteration() > 0 && std::filesystem::exists(hang_file_))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // stuck: only a second signal ends it
    auto field = VelocityField::normal(ScalarField(context.mesh().n_vertices(), speed_));
    if (nan_at_ >= 0 && std::size_t(nan_at_) < field.normal_speed.size())  // a faulty model
      field.normal_speed[std::size_t(nan_at_)] = std::nan("");
    field.metrics.emplace_back("computes", double(computes_));
    return field;
  }

  void end_step(const StepOutcome& outcome) override {
    if (outcome.attempt == 0) {
      if (outcome.phi_next.empty()) return;
      if (!seen_first_substep_) previous_ = arrays_of(outcome.mesh), seen_first_substep_ = true;
    } else if (arrays_of(outcome.mesh) != previous_) {
      ++restore_mismatches_;
    }
  }

  Review review(const StepContext& candidate, int attempt) override {
    seen_first_substep_ = false;
    const int n = candidate.iteration();
    if (reject_every_ > 0 && n % reject_every_ == 0 && attempt == 0)
      return Review::reject("first candidate of step " + std::to_string(n));
    ++accepted_;
    Review r = n == stop_at_ ? Review::accept_and_stop("asked to stop at iteration " + std::to_string(n))
                             : Review::accept();
    if (grow_dt_ > 0) r.next_dt = candidate.dt() * grow_dt_;
    r.metrics = {{"accepted", double(accepted_)},
                 {"restore_mismatches", double(restore_mismatches_)},
                 {"next_dt", r.next_dt}};
    return r;
  }

  void save_state(ModelState& state) const override {
    state.version = 1;
    state.set("accepted", std::vector<std::int64_t>{accepted_});
    state.set("computes", std::vector<std::int64_t>{computes_});
  }
  void load_state(const ModelState& state) override {
    accepted_ = state.integers("accepted").at(0);
    computes_ = state.integers("computes").at(0);
  }

 private:
  double speed_ = 1;
  std::int64_t reject_every_ = 0, stop_at_ = -1;
  double grow_dt_ = 0;
  bool freeze_ = false;
  std::int64_t nan_at_ = -1;
  std::string hang_file_;
  std::int64_t accepted_ = 0;
  std::int64_t computes_ = 0;
  int restore_mismatches_ = 0;
  bool seen_first_substep_ = false;
  std::vector<double> previous_;
};

}  // namespace

BODYFIT_PLUGIN(LifecycleModel)
