// Claims the next major ABI: the loader must refuse it before calling anything else (creating
// the model would abort the test).
#include <bodyfit/velocity_model.hpp>

#include <cstdlib>

BODYFIT_PLUGIN_EXPORT std::uint32_t bodyfit_plugin_abi() { return (bodyfit::kPluginAbiMajor + 1) << 16; }
BODYFIT_PLUGIN_EXPORT bodyfit::VelocityModel* bodyfit_create() { std::abort(); }
BODYFIT_PLUGIN_EXPORT void bodyfit_destroy(bodyfit::VelocityModel*) { std::abort(); }
