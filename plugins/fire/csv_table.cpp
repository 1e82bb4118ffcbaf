#include "csv_table.hpp"

#include <bodyfit/app/clock_time.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace bodyfit::fire {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string> split_fields(std::string_view text) {
  std::vector<std::string> fields;
  while (true) {
    const std::size_t comma = text.find(',');
    fields.emplace_back(trim(text.substr(0, comma)));
    if (comma == std::string_view::npos) return fields;
    text.remove_prefix(comma + 1);
  }
}

Csv parse_stream(std::istream& in, const std::filesystem::path& file, std::string_view expected) {
  Csv csv{.file = file};
  std::string text;
  for (long line = 1; std::getline(in, text); ++line) {
    std::string_view view = text;
    if (line == 1 && view.starts_with("\xEF\xBB\xBF")) view.remove_prefix(3);  // a spreadsheet's BOM
    view = trim(view);
    if (view.empty() || view.front() == '#') continue;
    std::vector<std::string> fields = split_fields(view);
    if (csv.columns.empty()) {
      for (const auto& name : fields)
        if (name.empty() || std::count(fields.begin(), fields.end(), name) > 1)
          throw file_error(file, line, fmt::format("the header '{}' has an empty or repeated column name (expected {})",
                                                   view, expected));
      csv.columns = std::move(fields);
      csv.header_line = line;
      continue;
    }
    if (fields.size() != csv.columns.size())
      throw file_error(file, line, fmt::format("{} field(s), the header has {} ({})", fields.size(), csv.columns.size(),
                                               fmt::join(csv.columns, ",")));
    csv.rows.push_back({line, std::move(fields)});
  }
  if (csv.columns.empty()) throw file_error(file, fmt::format("no header line (expected {})", expected));
  if (csv.rows.empty()) throw file_error(file, csv.header_line, fmt::format("no row after the header (expected {})", expected));
  return csv;
}

}  // namespace

std::size_t Csv::column(std::string_view name) const {
  return std::size_t(std::find(columns.begin(), columns.end(), name) - columns.begin());
}

Csv read_csv(const std::filesystem::path& file, std::string_view what, std::string_view expected) {
  std::ifstream in(file);
  if (!in) throw file_error(file, fmt::format("cannot open {} (expected a CSV file: {})", what, expected));
  return parse_stream(in, file, expected);
}

Csv parse_csv(std::string_view text, const std::filesystem::path& file, std::string_view expected) {
  std::istringstream in{std::string(text)};
  return parse_stream(in, file, expected);
}

void require_columns(const Csv& csv, const std::vector<std::string_view>& required, std::string_view expected) {
  for (const auto& name : csv.columns)
    if (std::find(required.begin(), required.end(), name) == required.end())
      throw file_error(csv.file, csv.header_line, fmt::format("unknown column '{}' (expected {})", name, expected));
  for (std::string_view name : required)
    if (!csv.has(name))
      throw file_error(csv.file, csv.header_line, fmt::format("no column '{}' (expected {})", name, expected));
}

double finite_number(const Csv& csv, const CsvRow& row, std::string_view column) {
  std::string_view text = row.fields[csv.column(column)];
  if (text.starts_with('+')) text.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty())
    throw file_error(csv.file, row.line, fmt::format("{}: '{}' is not a number", column, row.fields[csv.column(column)]));
  if (!std::isfinite(value))
    throw file_error(csv.file, row.line, fmt::format("{}: {} is not a finite number", column, text));
  return value;
}

std::vector<double> read_series_times(const Csv& csv, bool& clock_times) {
  std::vector<double> times;
  for (std::size_t k = 0; k < csv.rows.size(); ++k) {
    const CsvRow& row = csv.rows[k];
    const std::string& text = row.fields[csv.column("time")];
    double time = 0;
    bool clock = false;
    if (const std::optional<double> date = parse_iso8601(text)) {
      time = *date;
      clock = true;
    } else {
      try {
        time = finite_number(csv, row, "time");
      } catch (const InputError&) {
        throw file_error(csv.file, row.line,
                         fmt::format("time: '{}' is neither a number of seconds after t = 0 nor an ISO 8601 date-time "
                                     "with its zone (2026-07-14T13:00:00Z)",
                                     text));
      }
    }
    if (k == 0) clock_times = clock;
    if (clock != clock_times)
      throw file_error(csv.file, row.line,
                       fmt::format("time: '{}' is {}, the first time is {}: give every time the same way", text,
                                   clock ? "a date-time" : "in seconds", clock ? "in seconds" : "a date-time"));
    if (k > 0 && !(time > times.back()))
      throw file_error(csv.file, row.line,
                       fmt::format("time {} is not after the previous row's (line {}): times must increase", text,
                                   csv.rows[k - 1].line));
    times.push_back(time);
  }
  return times;
}

std::vector<double> series_run_times(const std::vector<double>& times, bool clock_times,
                                     std::optional<double> clock_start, const std::filesystem::path& file) {
  if (clock_times && !clock_start)
    throw file_error(file, "its times are ISO 8601 date-times: the case needs [time] start (the date-time of t = 0), "
                           "or give the times in seconds after t = 0");
  std::vector<double> run_times = times;
  if (clock_times)
    for (double& t : run_times) t -= *clock_start;
  return run_times;
}

}  // namespace bodyfit::fire
