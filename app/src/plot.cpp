#include <bodyfit/error.hpp>
#include <bodyfit/app/plot.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace bodyfit {
namespace {

struct Axis {
  bool log = false;
  double lo = 0, hi = 1;  // in plot coordinates (log10 of the value on a log axis)
  double to_plot(double value) const { return log ? std::log10(value) : value; }
  bool usable(double value) const { return std::isfinite(value) && (!log || value > 0); }

  void fit(double min_value, double max_value) {
    lo = to_plot(min_value), hi = to_plot(max_value);
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (log) {
      lo = std::floor(lo + 1e-9), hi = std::ceil(hi - 1e-9);
      if (hi <= lo) hi = lo + 1;
    } else {
      double span = hi - lo;
      if (span <= 0) span = std::max(1.0, std::abs(lo)), lo -= span / 2, hi += span / 2;
      lo -= 0.05 * span, hi += 0.05 * span;
    }
  }
  /// Tick positions (plot coordinates) and their labels.
  std::vector<std::pair<double, std::string>> ticks() const {
    std::vector<std::pair<double, std::string>> out;
    if (log) {
      for (double e = lo; e <= hi + 1e-9; e += 1) out.emplace_back(e, fmt::format("1E{}", int(std::lround(e))));
      return out;
    }
    double raw = (hi - lo) / 6;
    double magnitude = std::pow(10, std::floor(std::log10(raw)));
    double step = magnitude;
    for (double m : {1.0, 2.0, 5.0, 10.0})
      if (m * magnitude >= raw) {
        step = m * magnitude;
        break;
      }
    for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) {
      double value = std::abs(t) < 1e-12 * step ? 0 : t;
      out.emplace_back(value, fmt::format("{:.4g}", value));
    }
    return out;
  }
};

/// Minor ticks of a log axis (2..9 × each decade).
std::vector<double> minor_ticks(const Axis& axis) {
  std::vector<double> out;
  if (!axis.log) return out;
  for (double e = axis.lo; e < axis.hi - 1e-9; e += 1)
    for (int m = 2; m <= 9; ++m) out.push_back(e + std::log10(double(m)));
  return out;
}

}  // namespace

Rgb series_color(std::size_t i) {
  static const Rgb palette[10] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},   {148, 103, 189},
                                  {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}};
  return palette[i % 10];
}

Image plot(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  if (options.width < 200 || options.height < 150) throw InputError("plot: image must be at least 200×150");
  Image image(options.width, options.height);
  Axis ax{options.log_x}, ay{options.log_y};
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size()) throw InputError(fmt::format("plot: series '{}' has {} x and {} y", s.label, s.x.size(), s.y.size()));
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (ax.usable(s.x[i]) && ay.usable(s.y[i]))
        xmin = std::min(xmin, s.x[i]), xmax = std::max(xmax, s.x[i]), ymin = std::min(ymin, s.y[i]),
        ymax = std::max(ymax, s.y[i]);
  }
  if (!(xmin <= xmax)) xmin = options.log_x ? 1 : 0, xmax = options.log_x ? 10 : 1;
  if (!(ymin <= ymax)) ymin = options.log_y ? 1 : 0, ymax = options.log_y ? 10 : 1;
  ax.fit(xmin, xmax);
  ay.fit(ymin, ymax);

  const int left = 80, right = options.width - 20, top = options.title.empty() ? 30 : 45, bottom = options.height - 50;
  auto px = [&](double x) { return left + (ax.to_plot(x) - ax.lo) / (ax.hi - ax.lo) * (right - left); };
  auto py = [&](double y) { return bottom - (ay.to_plot(y) - ay.lo) / (ay.hi - ay.lo) * (bottom - top); };
  auto gx = [&](double t) { return left + (t - ax.lo) / (ax.hi - ax.lo) * (right - left); };
  auto gy = [&](double t) { return bottom - (t - ay.lo) / (ay.hi - ay.lo) * (bottom - top); };

  const Rgb ink{20, 20, 20}, grid{225, 225, 225}, minor{242, 242, 242};
  for (double t : minor_ticks(ax)) image.line(gx(t), top, gx(t), bottom, minor);
  for (double t : minor_ticks(ay)) image.line(left, gy(t), right, gy(t), minor);
  for (const auto& [t, label] : ax.ticks()) {
    image.line(gx(t), top, gx(t), bottom, grid);
    image.line(gx(t), bottom, gx(t), bottom + 5, ink);
    image.text(int(gx(t)) - Image::text_width(label) / 2, bottom + 9, label, ink);
  }
  for (const auto& [t, label] : ay.ticks()) {
    image.line(left, gy(t), right, gy(t), grid);
    image.line(left - 5, gy(t), left, gy(t), ink);
    image.text(left - 8 - Image::text_width(label), int(gy(t)) - 3, label, ink);
  }
  image.line(left, top, left, bottom, ink), image.line(right, top, right, bottom, ink);
  image.line(left, top, right, top, ink), image.line(left, bottom, right, bottom, ink);
  if (!options.title.empty())
    image.text((options.width - Image::text_width(options.title, 2)) / 2, 10, options.title, ink, 2);
  if (!options.x_label.empty())
    image.text((left + right - Image::text_width(options.x_label)) / 2, options.height - 18, options.x_label, ink);
  if (!options.y_label.empty()) image.text(8, top - 14, options.y_label, ink);

  for (const auto& s : series) {
    bool have_previous = false;
    double x0 = 0, y0 = 0;
    int segment = 0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!ax.usable(s.x[i]) || !ay.usable(s.y[i])) {
        have_previous = false;
        continue;
      }
      double x = px(s.x[i]), y = py(s.y[i]);
      if (s.lines && have_previous) {
        if (!s.dashed) {
          image.line(x0, y0, x, y, s.color, 2);
        } else {
          double length = std::hypot(x - x0, y - y0);
          int dashes = std::max(1, int(length / 8));
          for (int k = 0; k < dashes; ++k, ++segment)
            if (segment % 2 == 0)
              image.line(x0 + (x - x0) * k / dashes, y0 + (y - y0) * k / dashes, x0 + (x - x0) * (k + 1) / dashes,
                         y0 + (y - y0) * (k + 1) / dashes, s.color, 2);
        }
      }
      x0 = x, y0 = y, have_previous = true;
    }
    if (s.markers)
      for (std::size_t i = 0; i < s.x.size(); ++i)
        if (ax.usable(s.x[i]) && ay.usable(s.y[i]))
          image.fill_rect(int(px(s.x[i])) - 3, int(py(s.y[i])) - 3, int(px(s.x[i])) + 4, int(py(s.y[i])) + 4, s.color);
  }

  // Legend in a corner of the plot area (top right by default).
  int rows = 0, widest = 0;
  for (const auto& s : series)
    if (!s.label.empty()) ++rows, widest = std::max(widest, Image::text_width(s.label));
  if (rows > 0 && options.legend != LegendPosition::none) {
    const bool at_left = options.legend == LegendPosition::top_left || options.legend == LegendPosition::bottom_left;
    const bool at_bottom = options.legend == LegendPosition::bottom_left || options.legend == LegendPosition::bottom_right;
    const int width = widest + 44, height = rows * 14 + 8;
    int x0 = at_left ? left + 8 : right - 8 - width, x1 = x0 + width;
    int y0 = at_bottom ? bottom - 8 - height : top + 8, y1 = y0 + height;
    image.fill_rect(x0, y0, x1, y1, {255, 255, 255});
    image.line(x0, y0, x1, y0, ink), image.line(x0, y1, x1, y1, ink);
    image.line(x0, y0, x0, y1, ink), image.line(x1, y0, x1, y1, ink);
    int y = y0 + 6;
    for (const auto& s : series) {
      if (s.label.empty()) continue;
      image.line(x0 + 6, y + 3, x0 + 30, y + 3, s.color, 2);
      if (s.markers) image.fill_rect(x0 + 15, y, x0 + 22, y + 7, s.color);
      image.text(x0 + 36, y, s.label, ink);
      y += 14;
    }
  }
  return image;
}

void plot_png(const std::filesystem::path& file, const std::vector<PlotSeries>& series, const PlotOptions& options) {
  write_png(plot(series, options), file);
}

}  // namespace bodyfit
