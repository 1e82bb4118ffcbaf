#pragma once
// The console lines of a run: after each iteration where it stands — n/N or t/T, the share done
// and the time left — and the state (|G|, faces, worst quality, sub-steps, rejected steps), with
// the milliseconds of each stage when verbose; and a summary at the end (iterations, wall time,
// why it stopped, the files written).
#include <bodyfit/evolution.hpp>

#include <chrono>
#include <string>
#include <vector>

namespace bodyfit {

struct ProgressOptions {
  std::string time_unit;    ///< "s", or "" when the case's time has no unit
  std::string length_unit;  ///< "m", or ""
  bool verbose = false;     ///< the stage times on every line
};

class Progress {
 public:
  /// For a run evolving with `options` from `start`.
  Progress(const EvolutionOptions& options, const RunState& start, ProgressOptions settings);
  /// The line of an accepted iteration (spdlog info).
  void iteration(const IterationRecord& record);
  /// "[12/50 24 %, 1 min 12 s left]" for the share done `done` (0 to 1) at iteration n and time t.
  std::string position(int iteration, double time) const;
  /// The closing lines: what ended the run, after how many iterations and how long, and where
  /// its files are.
  void summary(const EvolutionResult& result, const std::string& directory, const std::vector<std::string>& files) const;

 private:
  double done(int iteration, double time) const;

  EvolutionOptions options_;
  RunState start_;
  ProgressOptions settings_;
  double start_done_ = 0;
  std::chrono::steady_clock::time_point clock_start_;
};

/// A wall-clock duration for a person: "0.4 s", "12 s", "3 min 05 s", "2 h 07 min".
std::string format_duration(double seconds);

}  // namespace bodyfit
