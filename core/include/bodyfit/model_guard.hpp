#pragma once
// A velocity model as the driver calls it: every call into the plugin is one stage of one
// iteration, and a failure there says so.
//
//   GuardedModel guarded(loaded.model(), start.iteration);
//   evolve(mesh, guarded, options, start, hooks);
//
// Any exception the model throws — std::exception or not (throw 42) — becomes a PluginError
// "model '<name>' failed in <stage> at iteration <n>: <what>" (ExitCode::Plugin), its message
// copied while the plugin is loaded (an exception's vtable may live in the plugin); but an
// InputError stays one, with the same words (ExitCode::Input): the contract's way for a model to
// say that the user's input is wrong, which some models can only see once they have the mesh (a
// volume model given a surface that is not closed).
// The iteration is StepContext::iteration() of the call: n for compute and end_step on T^n, n + 1
// for the review of the candidate T^{n+1}, the state saved or loaded for save_state/load_state, the
// final state for finish.
//
// With report_model_crashes(), a crash inside a call (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT)
// prints the model, the stage and the iteration to stderr (an async-signal-safe write) before the
// process dies of the signal, as it would have without the report; and exit() called inside a call
// is a model failure: the same report, and exit code 4 instead of the model's status.
#include <bodyfit/velocity_model.hpp>

#include <string>

namespace bodyfit {

/// Install the crash report (once per process) for the model `name`.
void report_model_crashes(const std::string& name);

/// A call into the model that has not returned after `seconds` ends the process with exit code 4
/// and a report naming the model, the stage and the iteration (the last checkpoint on disk is
/// intact): a model stuck in a loop or waiting forever stops on its own under a batch scheduler.
/// A watchdog thread, started by the first call; 0 turns the limit off.
void limit_model_calls(double seconds);

/// Marks a call into the plugin for the crash report while it lives (GuardedModel uses it; the
/// driver around configure_model). Not nested.
class PluginCall {
 public:
  PluginCall(const char* stage, int iteration);
  ~PluginCall();
  PluginCall(const PluginCall&) = delete;
  PluginCall& operator=(const PluginCall&) = delete;
};

/// A configured model (configure_model: its InputError on a bad parameter is the user's input).
class GuardedModel final : public VelocityModel {
 public:
  /// `iteration`: where the run starts (the state load_state restores on --resume); `abi`: the
  /// plugin's (LoadedModel::abi), so that a member its ABI does not have is never called.
  GuardedModel(VelocityModel& model, int iteration, std::uint32_t abi = kPluginAbi);

  std::string_view name() const override { return name_; }
  std::string_view version() const override { return model_.version(); }
  std::string_view description() const override { return model_.description(); }
  std::vector<ParameterDecl> parameters() const override { return model_.parameters(); }
  std::vector<OutputDecl> outputs() const override { return model_.outputs(); }
  std::vector<std::string> output_files() const override { return model_.output_files(); }
  void configure(Parameters& parameters) override;
  ModelNeeds needs() const override;
  VelocityField compute(const StepContext& context) override;
  void end_step(const StepOutcome& outcome) override;
  Review review(const StepContext& candidate, int attempt) override;
  void save_state(ModelState& state) const override;
  void load_state(const ModelState& state) override;
  void finish(const StepContext& final_state, ModelOutputs& outputs) override;
  /// The model's nuclei (none from a plugin built before ABI 3.1), each checked against T^n.
  std::vector<Nucleus> nuclei(const StepContext& state, int attempt) override;

 private:
  template <class Call>
  auto guarded(const char* stage, int iteration, Call&& call) const -> decltype(call());

  VelocityModel& model_;
  std::string name_;
  int iteration_;  ///< the last iteration seen (the start, compute's, review's)
  int step_;       ///< the iteration of the last compute (end_step's)
  std::uint32_t abi_;
};

}  // namespace bodyfit
