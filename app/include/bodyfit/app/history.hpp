#pragma once
// history.csv: one row per state of a run (row 0 the initial state, row n + 1 the state after
// iteration n with what it cost), the same columns in every row so numpy.loadtxt, pandas and
// spreadsheets read it as it is. A metric a row lacks is written as "nan".
//
// The file is rewritten atomically after every row. Row 0 is held back until the first iteration
// names the model's metric columns; a run resumed from iteration 0 writes it again.
#include <bodyfit/evolution.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

class RunHistory {
 public:
  /// The fixed columns, before the model's metrics.
  static const std::vector<std::string>& fixed_columns();

  explicit RunHistory(std::filesystem::path file);
  /// Keep the rows of an earlier run up to `last_iteration` (for --resume); true when the file
  /// had a row for every iteration up to it.
  bool resume(int last_iteration);
  /// Append the row of a state (written at once, except row 0 — see above).
  void add(const IterationRecord& record);
  /// Write what is held (row 0 of a run that made no iteration).
  void flush() const { write(); }
  std::size_t rows() const { return rows_.size(); }

 private:
  void write() const;

  std::filesystem::path file_;
  std::vector<std::string> metric_names_;          ///< model columns, from the first iteration
  std::vector<std::vector<std::string>> rows_;     ///< cells of the fixed columns then the metrics
  std::vector<std::vector<std::pair<std::string, std::string>>> metrics_;  ///< per row, by name
};

}  // namespace bodyfit
