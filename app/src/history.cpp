#include <bodyfit/atomic_file.hpp>
#include <bodyfit/app/history.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <sstream>

namespace bodyfit {
namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

std::vector<std::string> fixed_cells(const IterationRecord& r) {
  auto ms = [](double v) { return fmt::format("{:.3f}", v); };
  return {fmt::format("{}", r.iteration),       fmt::format("{:.17g}", r.time),
          fmt::format("{:.17g}", r.dt),         fmt::format("{:.17g}", r.area),
          fmt::format("{:.17g}", r.interface_length), fmt::format("{}", r.components),
          fmt::format("{:.6g}", r.min_quality), fmt::format("{:.6g}", r.mean_quality),
          fmt::format("{}", r.vertices),        fmt::format("{}", r.faces),
          fmt::format("{}", r.substeps),        fmt::format("{}", r.rejections),
          ms(r.ms.velocity),                    ms(r.ms.distance),
          ms(r.ms.advect),                      ms(r.ms.discretize),
          ms(r.ms.remesh),                      ms(r.ms.review),
          ms(r.ms.output),                      ms(r.ms.total())};
}

}  // namespace

const std::vector<std::string>& RunHistory::fixed_columns() {
  static const std::vector<std::string> columns = {
      "iteration",  "time",          "dt",         "area",         "interface_length", "components",
      "min_quality", "mean_quality", "vertices",   "faces",        "substeps",         "rejections",
      "ms_velocity", "ms_distance",  "ms_advect",  "ms_discretize", "ms_remesh",       "ms_review",
      "ms_output",   "ms_total"};
  return columns;
}

RunHistory::RunHistory(std::filesystem::path file) : file_(std::move(file)) {}

bool RunHistory::resume(int last_iteration) {
  std::ifstream in(file_);
  std::string line;
  if (!std::getline(in, line)) return false;
  // Columns by name, so a history written by an older bodyfit (other fixed columns) carries over.
  const std::vector<std::string> header = split_csv(line);
  const auto& fixed = fixed_columns();
  for (std::size_t c = 0; c < header.size(); ++c)
    if (std::find(fixed.begin(), fixed.end(), header[c]) == fixed.end()) metric_names_.push_back(header[c]);
  int expected = 0;
  for (long number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const std::vector<std::string> cells = split_csv(line);
    int iteration = -1;
    const char* first = cells.empty() ? nullptr : cells[0].data();
    const auto [end, error] = first ? std::from_chars(first, first + cells[0].size(), iteration)
                                    : std::from_chars_result{nullptr, std::errc::invalid_argument};
    if (error != std::errc() || end != first + cells[0].size() || iteration < 0) {
      // Not a row this program wrote (appended by hand, a damaged disk): what follows is dropped;
      // the rows up to the checkpoint are what the resumed run keeps and writes again.
      spdlog::warn("{}:{}: not a history row ({}): it and the lines after it are dropped", file_.string(), number,
                   line.size() > 60 ? line.substr(0, 60) + "..." : line);
      break;
    }
    if (iteration > last_iteration) break;
    if (iteration != expected) return false;  // a gap: the caller starts over
    std::vector<std::string> row(fixed.size(), "nan");
    std::vector<std::pair<std::string, std::string>> metrics;
    for (std::size_t c = 0; c < header.size() && c < cells.size(); ++c) {
      auto it = std::find(fixed.begin(), fixed.end(), header[c]);
      if (it != fixed.end()) row[std::size_t(it - fixed.begin())] = cells[c];
      else metrics.emplace_back(header[c], cells[c]);
    }
    rows_.push_back(std::move(row));
    metrics_.push_back(std::move(metrics));
    ++expected;
  }
  return expected == last_iteration + 1;
}

void RunHistory::add(const IterationRecord& record) {
  const auto& fixed = fixed_columns();
  for (const auto& [name, value] : record.metrics)
    if (name.empty() || name.find_first_of(",\"\n\r") != std::string::npos ||
        std::find(fixed.begin(), fixed.end(), name) != fixed.end())
      throw PluginError(fmt::format("the model's metric '{}' at iteration {} cannot be a column of history.csv (a "
                                    "name without commas, quotes or line breaks, other than the driver's columns)",
                                    name, record.iteration));
  if (record.iteration > 0 && metric_names_.empty())
    for (const auto& [name, value] : record.metrics)
      if (std::find(fixed.begin(), fixed.end(), name) == fixed.end()) metric_names_.push_back(name);
  std::vector<std::pair<std::string, std::string>> metrics;
  for (const auto& [name, value] : record.metrics) metrics.emplace_back(name, fmt::format("{:.10g}", value));
  rows_.push_back(fixed_cells(record));
  metrics_.push_back(std::move(metrics));
  if (record.iteration > 0) write();
}

void RunHistory::write() const {
  write_atomically(file_, [&](std::ostream& out) {
    std::string header = fmt::format("{}", fmt::join(fixed_columns(), ","));
    for (const auto& name : metric_names_) header += "," + name;
    out << header << "\n";
    for (std::size_t r = 0; r < rows_.size(); ++r) {
      std::string line = fmt::format("{}", fmt::join(rows_[r], ","));
      for (const auto& name : metric_names_) {
        std::string cell = "nan";
        for (const auto& [n, v] : metrics_[r])
          if (n == name) cell = v;
        line += "," + cell;
      }
      out << line << "\n";
    }
  });
}

}  // namespace bodyfit
