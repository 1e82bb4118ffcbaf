// A run of a case (run.hpp).
#include <bodyfit/app/run.hpp>

namespace bodyfit {

LoadedModel load_case_model(const CaseConfig& config) {
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters, case_surface_source(config));
  return model;
}

}  // namespace bodyfit
