#pragma once
// Checkpoints: a binary snapshot of a run after a completed iteration — the mesh with every tag and
// φ, where the run stands (iteration, time, the Δt in force) and the velocity model's own state —
// from which `bodyfit run --resume` continues exactly as the uninterrupted run would have.
//
// Doubles are stored bit-exactly and OpenMesh's connectivity arrays as they are, so reading restores
// the very arrays that were written. Format 3 added the Δt in force, the model state and a checksum
// over everything before it; format 4 (this one) the effective case the run was started with
// (case_identity.hpp), which --resume compares with its own. Formats 1-3 are still read (then there
// is no case record; formats 1 and 2 have no model state either).
#include <bodyfit/mesh.hpp>
#include <bodyfit/model_state.hpp>

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace bodyfit {

/// Where a run stands between two iterations.
struct RunState {
  int iteration = 0;  ///< counter of the state
  double time = 0;    ///< its time
  double dt = 0;      ///< Δt of the next step (a model may have changed it; 0: the case's)
};

struct Checkpoint {
  SurfaceMesh mesh;
  RunState run;
  std::optional<ModelState> model;  ///< absent in formats 1 and 2
  std::string case_text;            ///< the effective case (canonical_case); empty: not recorded (formats 1-3)
  int format = 4;                   ///< the format the file was written in
};

/// A checkpoint taken out of a live run: the arrays, the run state and the model state encoded in
/// memory, so that the file can be written while the run goes on (checkpoint_writer.hpp). Taking a
/// snapshot into the same object again reuses its memory: a run allocates it once.
class CheckpointSnapshot {
 public:
  int iteration() const { return iteration_; }
  /// The bytes of the file (the checksum is filled in by seal()).
  std::string_view bytes() const { return {data_.get(), size_}; }
  /// Compute the checksum over the rest (the slow part after the copy: done by the writer).
  void seal();
  /// Give the memory back (the next take_snapshot allocates again): a snapshot is the size of the
  /// mesh, which a run should not hold between checkpoints.
  void release() {
    data_.reset();
    size_ = capacity_ = 0;
  }

 private:
  friend void take_snapshot(CheckpointSnapshot&, const SurfaceMesh&, const RunState&, const ModelState*,
                            std::string_view);
  std::unique_ptr<char[]> data_;
  std::size_t size_ = 0, capacity_ = 0;
  int iteration_ = -1;
};

/// Copy the state into `into` (one sequential pass over the arrays). The mesh must be
/// garbage-collected; `model` may be null (no model state stored); `case_text` is the run's
/// effective case (canonical_case; empty: none recorded).
void take_snapshot(CheckpointSnapshot& into, const SurfaceMesh& mesh, const RunState& run, const ModelState* model,
                   std::string_view case_text = {});
/// Seal and write a snapshot atomically (temporary + rename), then fsync it and its directory.
void save_checkpoint(const std::filesystem::path& file, CheckpointSnapshot& snapshot);

/// The mesh must be garbage-collected. `model` may be null (no model state stored).
void write_checkpoint(std::ostream& out, const SurfaceMesh& mesh, const RunState& run, const ModelState* model = nullptr);
/// Atomically (write to a temporary, then rename).
void save_checkpoint(const std::filesystem::path& file, const SurfaceMesh& mesh, const RunState& run,
                     const ModelState* model = nullptr);
/// Throws InputError naming `name` for anything but an intact checkpoint of a known format.
Checkpoint read_checkpoint(std::istream& in, const std::string& name = "checkpoint");
Checkpoint load_checkpoint(const std::filesystem::path& file);

/// Put `mesh` in the state a checkpoint reads back (garbage-collected, status flags cleared), so a
/// run resumed from a checkpoint continues exactly like the uninterrupted one. Linear, no copy.
void canonicalize(SurfaceMesh& mesh);

}  // namespace bodyfit
