#pragma once
// What a run leaves in its directory, written from the evolution's hooks: a VTU and its .pvd entry
// per state, a history row per iteration, checkpoints on the cadence (and always of the last
// completed iteration: at the end, on an interruption, on a failure that leaves it in memory), PNG
// snapshots, the final mesh, and the model's declared grids (model_files.hpp). The named fault
// points (fault_injection.hpp) are those of docs/reference/running.md.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/model_guard.hpp>

#include <atomic>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace bodyfit {

/// A test hook (`bodyfit run --inject-signal N:INT|KILL[:scheduled]`): the signal raised once
/// iteration N's history row and checkpoint are written (SIGINT exercises the clean stop, SIGKILL
/// a crash between two iterations). With ":scheduled" iteration N gets a checkpoint only if the
/// cadence asks for one (a crash between two checkpoints); the write in flight completes first.
struct InjectedSignal {
  int iteration = -1;
  int signal = 0;
  bool force_checkpoint = true;
};
/// Parse "N:INT", "N:KILL" with an optional ":scheduled" ("" gives no injection).
InjectedSignal parse_injected_signal(const std::string& text);

class RunOutputs {
 public:
  /// `stop`: raised on an interruption (the iteration it ends with is checkpointed whatever the
  /// cadence).
  RunOutputs(const CaseConfig& config, std::filesystem::path outdir, GuardedModel& model, const std::string& case_text,
             const std::atomic<bool>* stop, InjectedSignal inject = {});
  ~RunOutputs();
  RunOutputs(const RunOutputs&) = delete;
  RunOutputs& operator=(const RunOutputs&) = delete;

  /// A new run: the checkpoint of the start, first and waited for (any other file of the run then
  /// comes with a checkpoint to resume from), then row 0.
  void begin(const SurfaceMesh& mesh);
  /// A resumed run: the rows and the .pvd entries before the checkpoint's state.
  void resume(const SurfaceMesh& mesh, const RunState& run, const ModelState& model_state);
  /// The hooks that write all of it (EvolutionHooks::outputs included).
  EvolutionHooks hooks();
  /// After a failure: the write in flight completed, and where a resume would start said.
  void report_checkpoint();
  /// The files written so far, by kind, for the summary ("41 step_*.vtu", "history.csv", ...).
  std::vector<std::string> written() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bodyfit
