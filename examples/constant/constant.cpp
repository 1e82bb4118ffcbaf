// constant: the smallest velocity model — G grows along its normal at a constant speed.
//   [model]
//   name = "constant"
//   speed = 0.5
#include <bodyfit/velocity_model.hpp>

namespace {

class ConstantModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "constant"; }
  std::string_view description() const override { return "a constant normal speed (example plugin)"; }

  std::vector<bodyfit::ParameterDecl> parameters() const override {
    return {bodyfit::ParameterDecl::number("speed", "length/time", "the normal speed; < 0 shrinks G").fallback(1.0)};
  }

  void configure(bodyfit::Parameters& p) override { speed_ = p.number("speed"); }

  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    return bodyfit::VelocityField::normal(bodyfit::ScalarField(context.mesh().n_vertices(), speed_));
  }

 private:
  double speed_ = 1.0;
};

}  // namespace

BODYFIT_PLUGIN(ConstantModel)
