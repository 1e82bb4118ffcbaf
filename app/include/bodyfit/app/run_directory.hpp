#pragma once
// The output directory of `bodyfit run`: which files are the run's own (so that --overwrite removes
// those and nothing else, and a directory holding a previous run is recognised), and the repairs a
// resume makes (temporaries of killed writes, per-state files past the checkpoint).
//
// The run's own files: case.toml, checkpoint.bin, history.csv, series.pvd, final.mesh, final.sol,
// step_<n>.vtu, snap_<n>.png, and the temporaries of atomic writes (atomic_file.hpp). A model's
// own outputs (the fire model's arrival_time.asc) are not among them: their names are the model's.
#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

/// Whether `file_name` (a name, not a path) is one the run writes.
bool is_run_output(const std::string& file_name);
/// The run's own files in `dir` (sorted; empty when `dir` does not exist).
std::vector<std::filesystem::path> run_outputs(const std::filesystem::path& dir);
/// Remove them (--overwrite), and the files of `model_files` (VelocityModel::output_files); other
/// files and subdirectories stay. Throws IoError on a failure.
void remove_run_outputs(const std::filesystem::path& dir, const std::vector<std::string>& model_files = {});
/// Remove the temporaries left by writes of a killed process. Returns how many there were.
std::size_t remove_stale_temporaries(const std::filesystem::path& dir);
/// Remove the per-state files (step_<n>.vtu, snap_<n>.png) of states n ≥ `first`: on --resume
/// from the checkpoint of iteration `first`, the resumed run writes again those it should.
std::size_t remove_states_from(const std::filesystem::path& dir, int first);

}  // namespace bodyfit
