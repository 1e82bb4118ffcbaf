// windy: an example velocity model written outside the bodyfit tree.
//
// The front moves along its normal at the speed
//     v = max(0, base + wind · n_Σ),
// where n_Σ is the unit conormal (pointing out of G) extended to the whole surface: G grows faster
// downwind and does not grow upwind. The speed is then smoothed by H¹ regularisation over the
// length `smoothing` (0: no smoothing), which damps the kinks of max(0, ·).
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <algorithm>

namespace {

class WindyModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "windy"; }
  std::string_view version() const override { return "1.0"; }
  std::string_view description() const override {
    return "normal speed max(0, base + wind . n), H1-smoothed (example plugin)";
  }
  std::vector<bodyfit::ParameterInfo> parameters() const override {
    return {{"base", "1", "speed without wind (length/time, >= 0)"},
            {"wind", "[1, 0, 0]", "wind vector (length/time)"},
            {"smoothing", "0", "H1 smoothing length (length, >= 0; 0: none)"}};
  }

  void configure(const toml::table& table) override {
    bodyfit::Parameters p(table, "model");
    base_ = p.number("base", 1.0, {.min = 0});
    auto wind = p.numbers("wind", {1, 0, 0}, 3);
    wind_ = bodyfit::Vec3(wind[0], wind[1], wind[2]);
    smoothing_ = p.number("smoothing", 0.0, {.min = 0});
    p.reject_unknown();  // "unknown key 'wnid' in [model]; did you mean 'wind'?"
  }

  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    const bodyfit::VectorField& n = context.conormal();
    bodyfit::ScalarField speed(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) speed[i] = std::max(0.0, base_ + OpenMesh::dot(wind_, n[i]));
    speed = context.smooth(speed, smoothing_);

    double largest = 0;
    for (double s : speed) largest = std::max(largest, s);
    auto field = bodyfit::VelocityField::normal(speed);
    field.metrics.emplace_back("max_speed", largest);  // a column of history.csv
    field.point_fields.emplace_back("windy_speed", std::move(speed));  // a field of the VTU
    return field;
  }

 private:
  double base_ = 1.0;
  bodyfit::Vec3 wind_{1, 0, 0};
  double smoothing_ = 0.0;
};

}  // namespace

BODYFIT_PLUGIN(WindyModel)
