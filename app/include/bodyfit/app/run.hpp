#pragma once
// A run of a case, shared by `bodyfit run` and the members of `bodyfit ensemble`: the case read,
// its model loaded and configured, T^0 built (nothing written), then the evolution with the hooks
// of whatever keeps its outputs — a run directory (run_outputs.hpp) with progress lines on the
// console (progress.hpp), or an ensemble member's kept grids.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/model_guard.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <functional>
#include <optional>

namespace bodyfit {

/// The case's model: loaded from its plugin, told what S was built from, configured through its
/// declarations; a key of [model] it does not read with these settings is refused (InputError
/// naming the key, and why when the model says).
LoadedModel load_case_model(const CaseConfig& config);

/// Where a run's model comes from: load_case_model, or a model the caller makes (a Python object).
using ModelLoader = std::function<LoadedModel(const CaseConfig& config)>;

class Run {
 public:
  /// Load and configure the case's model, then build S, its reference and T^0. `output_dir`
  /// ("" for none) is where the model may write its own files (StepContext::output_dir). Give the
  /// case moved, not copied: a copy of a TOML table forgets the files its values came from, which
  /// the model's file names are resolved against.
  Run(CaseConfig config, const std::filesystem::path& output_dir, const ModelLoader& load_model = {});

  const CaseConfig& config() const { return config_; }
  LoadedModel& model() { return model_; }
  SurfaceMesh& mesh() { return setup_.mesh; }
  const EvolutionOptions& options() const { return setup_.options; }
  double mesh_size() const { return setup_.h; }

  /// The model behind the guard every call goes through (model_guard.hpp); `start` is the
  /// iteration the run starts from (the state a resume's load_state restores).
  GuardedModel& guarded(int start = 0);
  /// Algorithm 1 from `start` (a resume: the checkpoint's mesh is already in mesh()).
  EvolutionResult evolve(const RunState& start, const EvolutionHooks& hooks);

 private:
  CaseConfig config_;
  LoadedModel model_;
  CaseSetup setup_;
  std::optional<GuardedModel> guarded_;
};

}  // namespace bodyfit
