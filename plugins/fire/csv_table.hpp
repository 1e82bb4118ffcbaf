#pragma once
// The fire model's CSV inputs (wind series, fuel tables): a header line, comma-separated fields
// with their blanks trimmed, blank lines and lines starting with '#' skipped. Errors are
// InputError "<file>:<line>: …".
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bodyfit::fire {

struct CsvRow {
  long line = 0;
  std::vector<std::string> fields;
};

struct Csv {
  std::filesystem::path file{};
  long header_line = 0;
  std::vector<std::string> columns{};
  std::vector<CsvRow> rows{};

  /// The column's index, or columns.size() when absent.
  std::size_t column(std::string_view name) const;
  bool has(std::string_view name) const { return column(name) < columns.size(); }
};

/// Reads `file` (`what` names it in messages: "the wind series"; `expected` says what the header
/// should be). A header with an empty or repeated name, a row of another width, no header or no
/// row are errors.
Csv read_csv(const std::filesystem::path& file, std::string_view what, std::string_view expected);
/// The same from text (a table compiled into the program); `file` names it in messages.
Csv parse_csv(std::string_view text, const std::filesystem::path& file, std::string_view expected);

/// The columns must be exactly `required` (in any order).
void require_columns(const Csv& csv, const std::vector<std::string_view>& required, std::string_view expected);

/// The row's field in `column` as a finite number (a leading '+' allowed).
double finite_number(const Csv& csv, const CsvRow& row, std::string_view column);

/// The `time` column of a series: seconds after t = 0, or ISO 8601 date-times (seconds since the
/// epoch; `clock_times` set), all of one kind, strictly increasing.
std::vector<double> read_series_times(const Csv& csv, bool& clock_times);

/// Series times on a run's clock: the times as given, or date-times less `clock_start` (the
/// date-time of t = 0); InputError naming `file` when they are date-times and there is no start.
std::vector<double> series_run_times(const std::vector<double>& times, bool clock_times,
                                     std::optional<double> clock_start, const std::filesystem::path& file);

}  // namespace bodyfit::fire
