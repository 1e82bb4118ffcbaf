#pragma once
// The identity of a case: the effective case (the table after --set) as canonical text, recorded
// in every checkpoint so that `--resume` continues the case that was started, not another one.
//
// Canonical: toml++'s serialisation of the table (keys sorted, comments, layout and key order of
// the file gone), so the same case read from another directory, reformatted or with the same
// --set values compares equal; relative paths compare as written.
#include <toml++/toml.h>

#include <string>
#include <vector>

namespace bodyfit {

std::string canonical_case(const toml::table& effective);

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

}  // namespace bodyfit
