// Claims an older major ABI (1.0): the loader must refuse it before calling anything else (creating
// the model would abort the test).
#include <bodyfit/velocity_model.hpp>

#include <cstdlib>

// An old plugin: built against ABI 1.0, two interfaces ago.
BODYFIT_PLUGIN_EXPORT std::uint32_t bodyfit_plugin_abi() { return 1u << 16; }
BODYFIT_PLUGIN_EXPORT bodyfit::VelocityModel* bodyfit_create() { std::abort(); }
BODYFIT_PLUGIN_EXPORT void bodyfit_destroy(bodyfit::VelocityModel*) { std::abort(); }
