// Plots (app/src/plot.cpp, `bodyfit plot`): the legend's corner, and the options the benchmark
// suite uses (scripts/bench_suite.sh: stages against faces, log-log, legend at the top left).
#include "test_support.hpp"

#include <bodyfit/app/plot.hpp>

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

using namespace bodyfit;

namespace {

/// Pixels of exactly colour c in [x0, x1) × [y0, y1).
int count_exact(const Image& image, Rgb c, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += image.at(x, y) == c;
  return n;
}

}  // namespace

TEST_CASE("plot: the legend goes to the corner asked for, or nowhere") {
  // A line along the bottom (an invisible point raises the y range), so both top corners are empty
  // but for the legend.
  const Rgb red{200, 0, 0};
  PlotSeries s, room;
  s.label = "a", s.x = {0, 1}, s.y = {0, 0.1}, s.color = red;
  room.x = {0}, room.y = {1}, room.lines = room.markers = false;
  PlotOptions options;
  options.width = 400, options.height = 300;
  // The plot area is [80, 380] x [30, 250] without a title.
  auto top_left = [&](const Image& image) { return count_exact(image, red, 80, 30, 160, 70); };
  auto top_right = [&](const Image& image) { return count_exact(image, red, 300, 30, 380, 70); };

  const Image by_default = plot({s, room}, options);
  CHECK(top_left(by_default) == 0);
  CHECK(top_right(by_default) > 20);  // the legend's line and marker
  options.legend = LegendPosition::top_left;
  const Image at_top_left = plot({s, room}, options);
  CHECK(top_left(at_top_left) == top_right(by_default));
  CHECK(top_right(at_top_left) == 0);
  options.legend = LegendPosition::none;
  const Image without = plot({s, room}, options);
  CHECK(top_left(without) == 0);
  CHECK(top_right(without) == 0);
}

TEST_CASE("bodyfit plot: log-log stages against faces with --legend and --y-label, a bad corner is a usage error") {
  test::TempDir dir("plot_stages");
  std::ofstream(dir / "stages.csv") << "faces,velocity,remesh,total\n60000,10,50,80\n240000,45,190,300\n"
                                       "1000000,200,800,1200\n";
  const std::string csv = (dir / "stages.csv").string();
  auto ok = test::run_bodyfit("plot " + csv + " -x faces -y velocity -y remesh -y total --log-x --log-y --legend top-left"
                              " --y-label 'ms per iteration' -o " + (dir / "stages.png").string());
  REQUIRE_MESSAGE(ok.exit_code == 0, ok.output);
  const Image image = read_png(dir / "stages.png");
  CHECK(image.width == 800);
  CHECK(count_exact(image, series_color(0), 80, 30, 200, 80) > 0);  // the legend, at the top left
  auto bad = test::run_bodyfit("plot " + csv + " -x faces -y total --legend middle -o " + (dir / "bad.png").string());
  CHECK(bad.exit_code == 2);
  CHECK(bad.output.find("--legend") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "bad.png"));
}
