#pragma once
// The identity of a case: the effective case (the table after --set) as canonical text, recorded
// in every checkpoint so that `--resume` continues the case that was started, not another one.
//
// Canonical: toml++'s serialisation of the table (keys sorted, comments, layout and key order of
// the file gone), so the same case read from another directory, reformatted or with the same
// --set values compares equal; relative paths compare as written.
#include <toml++/toml.h>

#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

std::string canonical_case(const toml::table& effective);

/// The effective case with, under [input_files], a digest (size and FNV-1a 64 of the bytes) of
/// every file it names: each string value outside [output] that names an existing file (relative
/// to base_dir, the case file's directory, as the case's readers take it). Recorded in checkpoints,
/// so that --resume also notices a data file edited in between (a wind series, a DEM, a mesh) and
/// refuses it as another case. Keys: the dotted key of the value ("model.wind.file"), with "[i]"
/// for an element of an array.
toml::table with_input_digests(const toml::table& effective, const std::filesystem::path& base_dir);

/// A key whose value differs between two cases ("" where it is absent).
struct CaseChange {
  std::string key;     ///< dotted: "time.dt", "model.speed"
  std::string before;  ///< as TOML ("0.05", "'conormal'")
  std::string after;
};
/// The keys whose values differ between two canonical cases, in key order.
std::vector<CaseChange> case_changes(const std::string& before, const std::string& after);

/// Whether a resumed run may change `key` without --force: the end of the run (time.final_time,
/// time.iterations: extending a run) and the outputs ([output]), which leave the states up to the
/// checkpoint as they are.
bool resume_may_change(const std::string& key);
/// Whether `key` is one of with_input_digests' entries.
bool is_input_digest(const std::string& key);

}  // namespace bodyfit
