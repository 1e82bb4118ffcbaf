// windy: an example velocity model written outside the bodyfit tree.
//
// The front moves along its normal at the speed
//     v = max(0, base + wind · n_Σ),
// where n_Σ is the unit conormal (pointing out of G) extended to the whole surface: G grows faster
// downwind and does not grow upwind. The speed is then smoothed by H¹ regularisation over the
// length `smoothing` (0: no smoothing), which damps the kinks of max(0, ·).
//
// It also shows the step lifecycle (docs/plugins.md §5): with `max_growth` > 0 it rejects a
// candidate T^{n+1} whose area |G| grew by more than that fraction in one step (the driver then
// retries with Δt/2) and keeps the smaller Δt afterwards; the number of accepted steps and the
// areas so far are state it keeps across a resume.
#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <fmt/format.h>

#include <algorithm>

namespace {

/// |G|: the area of the faces inside G, from the context's cached face areas.
double region_area(const bodyfit::StepContext& context) {
  const auto& mesh = context.mesh();
  double area = 0;
  for (auto f : mesh.faces())
    if (mesh.inside(f)) area += context.face_areas()[f.idx()];
  return area;
}

class WindyModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "windy"; }
  std::string_view version() const override { return "2.0"; }
  std::string_view description() const override {
    return "normal speed max(0, base + wind . n), H1-smoothed (example plugin)";
  }
  std::vector<bodyfit::ParameterInfo> parameters() const override {
    return {{"base", "1", "speed without wind (length/time, >= 0)"},
            {"wind", "[1, 0, 0]", "wind vector (length/time)"},
            {"smoothing", "0", "H1 smoothing length (length, >= 0; 0: none)"},
            {"max_growth", "0", "reject a step growing |G| by more than this fraction (0: accept all)"}};
  }

  void configure(const toml::table& table) override {
    bodyfit::Parameters p(table, "model");
    base_ = p.number("base", 1.0, {.min = 0});
    auto wind = p.numbers("wind", {1, 0, 0}, 3);
    wind_ = bodyfit::Vec3(wind[0], wind[1], wind[2]);
    smoothing_ = p.number("smoothing", 0.0, {.min = 0});
    max_growth_ = p.number("max_growth", 0.0, {.min = 0});
    p.reject_unknown();  // "unknown key 'wnid' in [model]; did you mean 'wind'?"
  }

  // Ask the driver to keep T^n (so it can restore it) only when this model may reject.
  bodyfit::ModelNeeds needs() const override { return {.may_reject = max_growth_ > 0}; }

  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    const bodyfit::VectorField& n = context.conormal();
    bodyfit::ScalarField speed(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) speed[i] = std::max(0.0, base_ + OpenMesh::dot(wind_, n[i]));
    speed = context.smooth(speed, smoothing_);
    area_ = region_area(context);

    double largest = 0;
    for (double s : speed) largest = std::max(largest, s);
    auto field = bodyfit::VelocityField::normal(speed);
    field.metrics.emplace_back("max_speed", largest);  // a column of history.csv
    field.point_fields.emplace_back("windy_speed", std::move(speed));  // a scalar field of the VTU
    field.vector_fields.emplace_back("wind", bodyfit::VectorField(n.size(), wind_));  // a vector field
    return field;
  }

  bodyfit::Review review(const bodyfit::StepContext& candidate, int attempt) override {
    const double growth = region_area(candidate) / area_ - 1;
    if (max_growth_ > 0 && growth > max_growth_)
      return bodyfit::Review::reject(fmt::format("|G| grew by {:.1f} % (max_growth {:.1f} %)", 100 * growth, 100 * max_growth_));
    ++accepted_;
    areas_.push_back(region_area(candidate));
    bodyfit::Review r = bodyfit::Review::accept();
    if (attempt > 0) r.next_dt = candidate.dt();  // keep the step that worked
    r.metrics = {{"growth", growth}, {"accepted_steps", double(accepted_)}};
    return r;
  }

  // What a resumed run must continue from: written into every checkpoint, read on --resume.
  void save_state(bodyfit::ModelState& state) const override {
    state.version = 1;
    state.set("accepted_steps", std::vector<std::int64_t>{accepted_});
    state.set("areas", areas_);
  }
  void load_state(const bodyfit::ModelState& state) override {
    if (state.version != 1) throw bodyfit::InputError(fmt::format("windy: state version {} unknown", state.version));
    accepted_ = state.integers("accepted_steps").at(0);
    areas_ = state.numbers("areas");
  }

 private:
  double base_ = 1.0;
  bodyfit::Vec3 wind_{1, 0, 0};
  double smoothing_ = 0.0;
  double max_growth_ = 0.0;
  double area_ = 0;                 ///< |G^n|, from compute()
  std::int64_t accepted_ = 0;       ///< state: steps accepted so far
  std::vector<double> areas_;       ///< state: |G| after each accepted step
};

}  // namespace

BODYFIT_PLUGIN(WindyModel)
