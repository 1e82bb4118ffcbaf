// Rate-of-spread evaluations per second of Rothermel's model (the fire calculator's and the fire
// model's physics), for every Scott & Burgan fuel under varied moistures, winds and slopes.
//
//   bench_ros [--evaluations N] [--csv FILE]
//
// Three timings, each the median of 5 repeats, printed and written as CSV (what,evaluations,seconds,per_second):
//   full     a whole evaluation, as `bodyfit ros` makes one: the fuel bed under its moistures
//            (surface_fire), the head spread under a wind and a slope, the ellipse's normal rate;
//   vertex   what the fire model does per vertex and step: the head spread on the terrain from a
//            prepared fuel bed, and the ellipse's normal rate in the front's direction;
//   normal   the ellipse's normal rate alone (per front direction, three per vertex with Huygens' velocity).
#include "bench_args.hpp"

#include "fuel.hpp"
#include "rothermel.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <vector>

namespace {

using namespace bodyfit;
using namespace bodyfit::fire;

double median_seconds(const std::function<double()>& run) {
  std::vector<double> times;
  for (int r = 0; r < 5; ++r) {
    const auto start = std::chrono::steady_clock::now();
    volatile double sink = run();
    (void)sink;
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[2];
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t evaluations = 1000000;
  std::string csv = "ros.csv";
  bench::Arguments args("bench_ros", "usage: bench_ros [--evaluations N] [--csv FILE]\n");
  args.option("--evaluations", evaluations);
  args.option("--csv", csv);
  args.parse(argc, argv);

  const FuelTable table = fuel_table("scott_burgan40");
  std::vector<FuelModel> fuels;
  for (const auto& m : table.models)
    if (m.burnable()) fuels.push_back(m);
  std::vector<FuelMoisture> moistures;
  for (const char* s : {"D1L1", "D2L2", "D3L3", "D1L4", "D4L1"}) {
    FuelMoisture m;
    moisture_scenario(s, m);
    moistures.push_back(m);
  }
  std::vector<SurfaceFire> beds;
  for (const auto& f : fuels) beds.push_back(surface_fire(f, moistures[1]));
  auto wind = [](std::size_t i) { return Vec3(0.5 + double(i % 17) * 0.4, double(i % 5) - 2.0, 0); };
  auto normal_of = [](std::size_t i) {
    const double a = double(i % 64) * 0.098;
    return Vec3(std::cos(a), std::sin(a), 0);
  };
  auto terrain = [](std::size_t i) {
    const double tilt = double(i % 9) * 0.06;
    return Vec3(std::sin(tilt), 0, std::cos(tilt));
  };

  struct Row {
    const char* what;
    double seconds;
  };
  std::vector<Row> rows;
  rows.push_back({"full", median_seconds([&] {
                    double sum = 0;
                    for (std::size_t i = 0; i < evaluations; ++i) {
                      const SurfaceFire bed = surface_fire(fuels[i % fuels.size()], moistures[i % moistures.size()]);
                      const HeadSpread s = head_spread(bed, wind(i), Vec3(1, 0, 0), double(i % 7) * 0.1);
                      sum += ellipse_normal_rate(s, normal_of(i));
                    }
                    return sum;
                  })});
  rows.push_back({"vertex", median_seconds([&] {
                    double sum = 0;
                    for (std::size_t i = 0; i < evaluations; ++i) {
                      const HeadSpread s = head_spread_on_terrain(beds[i % beds.size()], terrain(i), wind(i), 0.4);
                      sum += ellipse_normal_rate(s, normal_of(i));
                    }
                    return sum;
                  })});
  const HeadSpread fixed = head_spread(beds[0], Vec3(2, 0, 0), Vec3(1, 0, 0), 0.2);
  rows.push_back({"normal", median_seconds([&] {
                    double sum = 0;
                    for (std::size_t i = 0; i < evaluations; ++i) sum += ellipse_normal_rate(fixed, normal_of(i));
                    return sum;
                  })});

  std::ofstream out(csv);
  out << "what,evaluations,seconds,per_second\n";
  for (const Row& r : rows) {
    const double rate = double(evaluations) / r.seconds;
    fmt::print("{:<7} {:>10} evaluations in {:8.4f} s: {:>12.0f} per second\n", r.what, evaluations, r.seconds, rate);
    out << fmt::format("{},{},{:.6f},{:.0f}\n", r.what, evaluations, r.seconds, rate);
  }
  return 0;
}
