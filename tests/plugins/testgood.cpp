// A working test model: normal speed = `value` everywhere; reports the iteration as a metric.
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

namespace {

class GoodModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "testgood"; }
  std::string_view version() const override { return "2.5"; }
  std::string_view description() const override { return "constant normal speed (test)"; }
  std::vector<bodyfit::ParameterInfo> parameters() const override {
    return {{"value", "0.5", "the normal speed"}};
  }
  void configure(const toml::table& table) override {
    bodyfit::Parameters p(table, "model");
    value_ = p.number("value", 0.5, {.min = 0});
    p.reject_unknown();
  }
  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    auto field = bodyfit::VelocityField::normal(bodyfit::ScalarField(context.mesh().n_vertices(), value_));
    field.metrics.emplace_back("iteration", context.iteration());
    return field;
  }

 private:
  double value_ = 0.5;
};

}  // namespace

BODYFIT_PLUGIN(GoodModel)
