// windy: an example velocity model written outside the bodyfit tree.
//
// The front moves along its normal at the speed
//     v = max(0, base + wind · n_Σ),
// where n_Σ is the unit conormal (pointing out of G) extended to the whole surface: G grows faster
// downwind and does not grow upwind. The speed is then smoothed by H¹ regularisation over the
// length `smoothing` (0: no smoothing), which damps the kinks of max(0, ·).
//
// It also shows the step lifecycle (docs/guide/writing_models.md §5): with `max_growth` > 0 it rejects a
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
  std::string_view version() const override { return "3.0"; }
  std::string_view description() const override {
    return "normal speed max(0, base + wind . n), H1-smoothed (example plugin)";
  }
  // Declared once: `bodyfit plugins --describe windy` prints them, configure() reads through them,
  // and a key of [model] that configure() does not read is refused before the run starts.
  std::vector<bodyfit::ParameterDecl> parameters() const override {
    using bodyfit::ParameterDecl;
    return {ParameterDecl::number("base", "length/time", "speed without wind").fallback(1.0).at_least(0),
            ParameterDecl::numbers("wind", 3, "length/time", "wind vector").fallback(std::vector<double>{1, 0, 0}),
            ParameterDecl::number("smoothing", "length", "H1 smoothing length (0: none)").fallback(0.0).at_least(0),
            ParameterDecl::number("max_growth", "1", "reject a step growing |G| by more than this fraction (0: accept "
                                                     "all)")
                .fallback(0.0)
                .at_least(0)};
  }
  std::vector<bodyfit::OutputDecl> outputs() const override {
    using bodyfit::OutputDecl;
    return {OutputDecl::metric("max_speed", "length/time", "the largest normal speed"),
            OutputDecl::vertex_field("windy_speed", "length/time", "the normal speed"),
            OutputDecl::vertex_field("wind", "length/time", "the wind (a vector)")};
  }

  void configure(bodyfit::Parameters& p) override {
    base_ = p.number("base");  // the declared default and range: "[model] base: -1 is out of range [0, inf)"
    auto wind = p.numbers("wind");
    wind_ = bodyfit::Vec3(wind[0], wind[1], wind[2]);
    smoothing_ = p.number("smoothing");
    max_growth_ = p.number("max_growth");
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
