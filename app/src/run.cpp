// A run of a case (run.hpp).
#include <bodyfit/app/run.hpp>

namespace bodyfit {

LoadedModel load_case_model(const CaseConfig& config) {
  LoadedModel model = load_model(config.model);
  report_model_crashes(std::string(model->name()));  // a crash in the plugin names it, from here on
  {
    PluginCall call("configure", -1);
    configure_model(model, config.model_parameters, case_surface_source(config));
  }
  return model;
}

Run::Run(CaseConfig config, const std::filesystem::path& output_dir, const ModelLoader& load_model)
    : config_(std::move(config)),
      model_(load_model ? load_model(config_) : load_case_model(config_)),
      setup_(setup_case(config_)) {
  setup_.options.output_dir = output_dir;
  setup_.options.height_field = config_.surface.height_field();
}

GuardedModel& Run::guarded(int start) {
  if (!guarded_) guarded_.emplace(model_.model(), start, model_.abi());
  return *guarded_;
}

EvolutionResult Run::evolve(const RunState& start, const EvolutionHooks& hooks) {
  return bodyfit::evolve(setup_.mesh, guarded(start.iteration), setup_.options, start, hooks);
}

}  // namespace bodyfit
