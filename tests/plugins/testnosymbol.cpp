// Exports the ABI and bodyfit_create but not bodyfit_destroy: the loader must refuse it.
#include <bodyfit/velocity_model.hpp>

namespace {
class Incomplete final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "testnosymbol"; }
  void configure(bodyfit::Parameters&) override {}
  bodyfit::VelocityField compute(const bodyfit::StepContext&) override { return {}; }
};
}  // namespace

BODYFIT_PLUGIN_EXPORT std::uint32_t bodyfit_plugin_abi() { return bodyfit::kPluginAbi; }
BODYFIT_PLUGIN_EXPORT bodyfit::VelocityModel* bodyfit_create() { return new Incomplete(); }
