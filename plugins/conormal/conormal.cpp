// The conormal velocity of the paper's first example, (4.1): V = ∇_S d_{G(t)}.
//
// ∇_S d is the unit conormal n_Σ on the interface ∂G (pointing out of G) and extends it to the
// whole surface as the gradient of the signed distance, so G grows at unit normal speed along the
// geodesics normal to its boundary. `speed` scales it (a negative speed shrinks G).
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <fmt/format.h>

namespace {

class ConormalModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "conormal"; }
  std::string_view version() const override { return "1.0"; }
  std::string_view description() const override {
    return "V = speed * grad_S d: the unit conormal extended by the gradient of the signed distance (paper (4.1))";
  }
  std::vector<bodyfit::ParameterInfo> parameters() const override {
    return {{"speed", "1", "factor multiplying V (length/time); a negative value shrinks G"}};
  }
  void configure(const toml::table& table) override {
    bodyfit::Parameters p(table, "model");
    speed_ = p.number("speed", 1.0);
    p.reject_unknown();
  }
  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    bodyfit::VectorField v = context.conormal();
    for (auto& x : v) x *= speed_;
    auto field = bodyfit::VelocityField::tangential(std::move(v));
    field.metrics.emplace_back("speed", speed_);
    return field;
  }

 private:
  double speed_ = 1.0;
};

}  // namespace

BODYFIT_PLUGIN(ConormalModel)
