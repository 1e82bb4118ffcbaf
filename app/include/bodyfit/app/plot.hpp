#pragma once
// Small line plots to PNG (linear or log-log), for run histories and convergence studies.
#include <bodyfit/app/render.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

struct PlotSeries {
  std::string label;               ///< legend entry ("" for none)
  std::vector<double> x, y;        ///< same length; non-finite (or ≤ 0 on a log axis) points are skipped
  Rgb color{31, 119, 180};
  bool lines = true;
  bool markers = true;
  bool dashed = false;
};

/// Corner of the plot area that holds the legend (none: no legend).
enum class LegendPosition { top_right, top_left, bottom_right, bottom_left, none };

struct PlotOptions {
  int width = 800, height = 600;
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;
  LegendPosition legend = LegendPosition::top_right;
};

/// A qualitative palette (10 distinct colours) for series i.
Rgb series_color(std::size_t i);

Image plot(const std::vector<PlotSeries>& series, const PlotOptions& options = {});
void plot_png(const std::filesystem::path& file, const std::vector<PlotSeries>& series, const PlotOptions& options = {});

}  // namespace bodyfit
