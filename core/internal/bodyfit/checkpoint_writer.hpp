#pragma once
// When and how a run writes its checkpoint: a cadence (every N iterations, every S seconds of wall
// clock) and a writer that copies the state on the loop's thread and leaves the encoding's checksum,
// the write, the fsync and the rename to a background thread — at most one write in flight.
//
//   CheckpointWriter writer(outdir / "checkpoint.bin", {.every = 0, .seconds = 30});
//   if (writer.due(n)) {
//     double ms = writer.snapshot(mesh, run, &state);  // waits for the previous write, copies
//     ... write the history row (with ms) ...
//     writer.start();                                  // returns at once
//   }
//   writer.wait();                                     // at the end: the last write is complete
#include <bodyfit/checkpoint.hpp>

#include <chrono>
#include <exception>
#include <filesystem>
#include <string>
#include <thread>

namespace bodyfit {

/// When a run checkpoints, besides its start, its end and an interruption. 0 turns a criterion off.
struct CheckpointCadence {
  int every = 0;        ///< at iterations that are multiples of this
  double seconds = 30;  ///< when this much wall-clock time has passed since the last snapshot
};

class CheckpointWriter {
 public:
  /// `case_text`: the run's effective case (canonical_case), recorded in every checkpoint.
  CheckpointWriter(std::filesystem::path file, CheckpointCadence cadence, std::string case_text = {});
  /// Waits for the write in flight (an error there is logged: a destructor cannot throw).
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;

  /// Whether the cadence asks for a checkpoint of `iteration`, just completed.
  bool due(int iteration) const;
  /// Wait for the previous write, then copy the state (take_snapshot). Returns the milliseconds
  /// the caller spent in both. Rethrows the previous write's error.
  double snapshot(const SurfaceMesh& mesh, const RunState& run, const ModelState* model);
  /// Write the last snapshot on the background thread.
  void start();
  /// Wait for the write in flight (if any) and rethrow its error. Returns the milliseconds waited.
  double wait();
  /// The iteration of the last snapshot, or of the checkpoint a resumed run started from (−1: none).
  int last_iteration() const { return last_iteration_; }
  /// A resumed run: its checkpoint is on disk already.
  void assume_written(int iteration) { last_iteration_ = iteration; }

 private:
  std::filesystem::path file_;
  CheckpointCadence cadence_;
  std::string case_text_;
  CheckpointSnapshot snapshot_;
  std::thread worker_;
  std::exception_ptr error_;
  std::chrono::steady_clock::time_point last_snapshot_;
  int last_iteration_ = -1;
};

}  // namespace bodyfit
