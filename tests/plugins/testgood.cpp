// A working test model: normal speed = `value` everywhere; reports the iteration as a metric.
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

namespace {

class GoodModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "testgood"; }
  std::string_view version() const override { return "3.0"; }
  std::string_view description() const override { return "constant normal speed (test)"; }
  std::vector<bodyfit::ParameterDecl> parameters() const override {
    return {bodyfit::ParameterDecl::number("value", "length/time", "the normal speed").fallback(0.5).at_least(0)};
  }
  std::vector<bodyfit::OutputDecl> outputs() const override {
    return {bodyfit::OutputDecl::metric("state", "1", "the state's iteration")};
  }
  void configure(bodyfit::Parameters& p) override { value_ = p.number("value"); }
  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    auto field = bodyfit::VelocityField::normal(bodyfit::ScalarField(context.mesh().n_vertices(), value_));
    field.metrics.emplace_back("state", context.iteration());
    return field;
  }

 private:
  double value_ = 0.5;
};

}  // namespace

BODYFIT_PLUGIN(GoodModel)
