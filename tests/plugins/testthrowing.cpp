// Loads fine, but configure() always rejects its parameters.
#include <bodyfit/error.hpp>
#include <bodyfit/velocity_model.hpp>

namespace {
class Throwing final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "testthrowing"; }
  void configure(bodyfit::Parameters&) override { throw bodyfit::InputError("the answer must be 42"); }
  bodyfit::VelocityField compute(const bodyfit::StepContext&) override { return {}; }
};
}  // namespace

BODYFIT_PLUGIN(Throwing)
