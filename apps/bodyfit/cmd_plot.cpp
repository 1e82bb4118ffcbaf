// bodyfit plot history.csv -y J -o J.png: line plots of run histories (any CSV with a header row),
// one series per (file, column); several files compare runs. --log-x / --log-y for log axes (e.g.
// time against mesh size), --label names the files' series, --legend moves the legend to a corner.
#include "commands.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/app/plot.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using namespace bodyfit;

struct PlotArguments {
  std::vector<std::string> files, columns, labels;
  std::string x = "iteration", output, title, y_label, size = "800x600", legend = "top-right";
  bool log_x = false, log_y = false;
};

/// The columns of a CSV file by name ("nan" and empty cells are NaN).
std::vector<std::pair<std::string, std::vector<double>>> read_columns(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw file_error(file, "cannot open");
  std::string line;
  if (!std::getline(in, line)) throw file_error(file, "empty: expected a header row");
  std::vector<std::pair<std::string, std::vector<double>>> columns;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) columns.emplace_back(name, std::vector<double>{});
  long number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::stringstream cells(line);
    std::size_t c = 0;
    for (std::string cell; std::getline(cells, cell, ',') && c < columns.size(); ++c) {
      char* end = nullptr;
      double value = std::strtod(cell.c_str(), &end);
      if (cell.empty() || end == cell.c_str()) value = std::nan("");
      columns[c].second.push_back(value);
    }
    if (c != columns.size())
      throw file_error(file, number, fmt::format("{} cells, the header has {} columns", c, columns.size()));
  }
  return columns;
}

const std::map<std::string, LegendPosition>& legend_corners() {
  static const std::map<std::string, LegendPosition> corners{{"top-right", LegendPosition::top_right},
                                                             {"top-left", LegendPosition::top_left},
                                                             {"bottom-right", LegendPosition::bottom_right},
                                                             {"bottom-left", LegendPosition::bottom_left},
                                                             {"none", LegendPosition::none}};
  return corners;
}

const std::vector<double>& column(const std::vector<std::pair<std::string, std::vector<double>>>& columns,
                                  const std::string& name, const fs::path& file) {
  for (const auto& [n, values] : columns)
    if (n == name) return values;
  std::string known;
  for (const auto& [n, values] : columns) known += (known.empty() ? "" : ", ") + n;
  throw file_error(file, fmt::format("no column '{}' (columns: {})", name, known));
}

int plot_command(const PlotArguments& args) {
  int w = 0, h = 0;
  char x = 0;
  if (std::sscanf(args.size.c_str(), "%d%c%d", &w, &x, &h) != 3 || (x != 'x' && x != 'X') || w < 64 || h < 64 ||
      w > 8192 || h > 8192)
    throw InputError(fmt::format("--size '{}': expected WxH with each in [64, 8192], e.g. 800x600", args.size));
  if (!args.labels.empty() && args.labels.size() != args.files.size())
    throw InputError(fmt::format("--label: {} labels for {} files", args.labels.size(), args.files.size()));
  std::vector<PlotSeries> series;
  for (std::size_t f = 0; f < args.files.size(); ++f) {
    const auto columns = read_columns(args.files[f]);
    const auto& xs = column(columns, args.x, args.files[f]);
    for (const auto& name : args.columns) {
      PlotSeries s;
      s.x = xs;
      s.y = column(columns, name, args.files[f]);
      const std::string run = args.labels.empty() ? fs::path(args.files[f]).parent_path().filename().string() : args.labels[f];
      s.label = args.files.size() > 1 ? (args.columns.size() > 1 ? run + ": " + name : run) : name;
      s.color = series_color(series.size());
      s.markers = s.x.size() <= 60;
      series.push_back(std::move(s));
    }
  }
  PlotOptions options;
  options.width = w, options.height = h;
  options.title = args.title;
  options.x_label = args.x;
  options.y_label = !args.y_label.empty() ? args.y_label : args.columns.size() == 1 ? args.columns.front() : "";
  options.log_x = args.log_x, options.log_y = args.log_y;
  options.legend = legend_corners().at(args.legend);
  plot_png(args.output, series, options);
  spdlog::info("{} series -> {}", series.size(), args.output);
  return 0;
}

bodyfit::cli::Command setup_plot(CLI::App& app) {
  auto* cmd = app.add_subcommand("plot", "plot columns of history.csv files (or any CSV with a header) to a PNG");
  auto args = std::make_shared<PlotArguments>();
  // No ExistingFile check: a missing file is an input error (exit 1), as for every reader.
  cmd->add_option("csv", args->files, "CSV files (e.g. out/history.csv; several compare runs)")->required();
  cmd->add_option("-y,--column", args->columns, "column(s) to plot (repeatable)")->required();
  cmd->add_option("-x", args->x, "column of the horizontal axis")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "output .png")->required();
  cmd->add_option("--label", args->labels, "legend label per file (default: the file's directory)");
  cmd->add_option("--title", args->title, "plot title");
  cmd->add_option("--y-label", args->y_label, "label of the vertical axis (default: the column, if only one)");
  cmd->add_option("--legend", args->legend, "corner of the legend")
      ->check(CLI::IsMember(legend_corners()))
      ->capture_default_str();
  cmd->add_option("--size", args->size, "image size WxH")->capture_default_str();
  cmd->add_flag("--log-x", args->log_x, "logarithmic x axis");
  cmd->add_flag("--log-y", args->log_y, "logarithmic y axis");
  return {cmd, [args]() { return plot_command(*args); }};
}

BODYFIT_COMMAND(86, setup_plot);

}  // namespace
