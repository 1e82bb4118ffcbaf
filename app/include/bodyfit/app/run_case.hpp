#pragma once
// A case run into its output directory, from set-up to the last file: what `bodyfit run` does and
// what bodyfit.run does from Python. The caller owns the process: its signal handlers raise
// `interrupted`, and the model may come from elsewhere than a plugin (`load_model`).
#include <bodyfit/app/run.hpp>
#include <bodyfit/app/run_outputs.hpp>

#include <toml++/toml.h>

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace bodyfit {

struct RunRequest {
  /// The case file; or, with `case_table`, the name the case goes by in messages and in the
  /// default output directory (may be "").
  std::filesystem::path case_file;
  /// A case given as a table (a Python dict): its relative file names resolve against `case_dir`.
  std::optional<toml::table> case_table;
  std::filesystem::path case_dir;
  std::vector<std::string> sets;     ///< "dotted.key=value" overrides, in order
  std::filesystem::path output_dir;  ///< "": <case name>.out
  bool resume = false;     ///< continue from the directory's checkpoint
  bool overwrite = false;  ///< replace a previous run there (its own files only)
  bool force = false;      ///< resume even though the case differs from the checkpoint's
  bool verbose = false;    ///< the stage times on every progress line
  bool progress = true;    ///< a line per iteration on the console
  ModelLoader load_model;  ///< empty: the plugin the case names (load_case_model)
  /// Raised by the caller's signal handlers: the iteration in progress ends and is checkpointed.
  const std::atomic<bool>* interrupted = nullptr;
  InjectedSignal inject;  ///< tests: a signal raised after an iteration
};

struct RunOutcome {
  EvolutionResult result;
  std::filesystem::path output_dir;
  int exit_code = 0;  ///< 0, ExitCode::Interrupted (130) or ExitCode::Plugin (a rejected step)
};

/// Read the case, set the run up (nothing is written until it is), then evolve with the outputs of
/// a run directory. Errors are exceptions of error.hpp; an exception during the evolution leaves
/// the last completed iteration checkpointed.
RunOutcome run_case(const RunRequest& request);

}  // namespace bodyfit
