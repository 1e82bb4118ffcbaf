#pragma once
// A run of a case, shared by `bodyfit run` and the members of `bodyfit ensemble`.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/plugin_loader.hpp>

namespace bodyfit {

/// The case's model: loaded from its plugin, told what S was built from, configured through its
/// declarations; a key of [model] it does not read with these settings is refused (InputError
/// naming the key, and why when the model says).
LoadedModel load_case_model(const CaseConfig& config);

}  // namespace bodyfit
