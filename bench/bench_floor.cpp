// How far each stage of an iteration is from the machine's limit: the least data the stage must read
// and write (one pass over the arrays its result depends on), divided by the memory bandwidth this
// machine measures, beside the stage's time on the conormal case (docs/validation/performance.md,
// "The physical floor").
//
//   bench_floor [--case meshes/cases/sphere_cap.toml] [--h 0.0054] [--iterations 4] [--threads N]
//               [--whole-surface] [-o floor.csv]
//
// The floor of a stage is what streaming its data once would cost: a stage at 10× its floor spends
// 90 % of its time on something else than moving the data it needs (latency of irregular accesses,
// arithmetic, a sequential algorithm, passes over larger data structures than the minimum).
#include "bench_args.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

using namespace bodyfit;

namespace {

struct Bandwidth {
  double read = 0, copy = 0;  // GB/s: bytes read, and bytes read + written, per second
};

/// The best of five: a parallel sum over 256 MiB (read), and a parallel copy of 256 MiB (read and
/// write), in blocks of 1 MiB.
Bandwidth measure_bandwidth() {
  const std::size_t n = std::size_t(256) << 20 >> 3;
  std::vector<double> a(n, 1.0), b(n, 0.0);
  const std::size_t block = std::size_t(1) << 17;
  const std::size_t blocks = n / block;
  auto seconds = [](auto&& work) {
    const auto start = std::chrono::steady_clock::now();
    work();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  Bandwidth best;
  double sink = 0;
  for (int repeat = 0; repeat < 5; ++repeat) {
    const double read = seconds([&] {
      sink += tbb::parallel_reduce(
          tbb::blocked_range<std::size_t>(0, blocks), 0.0,
          [&](const tbb::blocked_range<std::size_t>& r, double sum) {
            // Four independent sums: one would wait for each addition (latency, not bandwidth).
            double s[4] = {0, 0, 0, 0};
            for (std::size_t i = r.begin() * block; i < r.end() * block; i += 4)
              for (int j = 0; j < 4; ++j) s[j] += a[i + std::size_t(j)];
            return sum + s[0] + s[1] + s[2] + s[3];
          },
          std::plus<>());
    });
    const double copy = seconds([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k < r.end(); ++k) std::memcpy(&b[k * block], &a[k * block], block * sizeof(double));
      });
    });
    best.read = std::max(best.read, double(n * sizeof(double)) / read * 1e-9);
    best.copy = std::max(best.copy, 2 * double(n * sizeof(double)) / copy * 1e-9);
  }
  if (sink < 0 || b[n / 2] != 1.0) std::fprintf(stderr, "bench_floor: the bandwidth loops were optimised away\n");
  return best;
}

/// The least data of each stage, in bytes, for nv vertices and nf faces: what its result depends on
/// and what it writes, each array once. Points 24 B, a scalar field 8 B and a vector field 24 B per
/// vertex; a face's corners 12 B and its neighbours across its edges 12 B.
struct StageData {
  const char* stage;
  const char* arrays;
  double bytes;
};

std::vector<StageData> stage_data(double nv, double nf) {
  return {
      {"velocity", "reads d, points, corners; writes V", nv * (8 + 24 + 24) + nf * 12},
      {"distance", "reads φ, points, corners; writes d", nv * (8 + 24 + 8) + nf * 12},
      {"advect", "reads φ, V, points, corners, neighbours; writes φ", nv * (8 + 24 + 24 + 8) + nf * (12 + 12)},
      {"discretize", "reads φ, points, corners (the cut changes a band)", nv * (8 + 24) + nf * 12},
      {"remesh", "reads points, corners (the sweep; the changes are a band)", nv * 24 + nf * 12},
  };
}

}  // namespace

int main(int argc, char** argv) {
  double h = 0.0054;
  int iterations = 4, threads = 0;
  bool whole_surface = false;
  std::string csv_path = "floor.csv", case_path = "meshes/cases/sphere_cap.toml";
  bench::Arguments args("bench_floor",
                        "usage: bench_floor [--case meshes/cases/sphere_cap.toml] [--h 0.0054] [--iterations 4]\n"
                        "                   [--threads N] [--whole-surface] [-o floor.csv]\n"
                        "  --case        the conormal case (run with h = hmax = --h, hmin = h/10, outputs off)\n"
                        "  --h           its mesh size (0.0054: about a million faces)\n"
                        "  --iterations  iterations run; the stage times are the medians after the first\n"
                        "  --threads     worker threads (default: every core)\n"
                        "  --whole-surface  d and the advection on the whole surface ([time] narrow_band = false)\n"
                        "  -o            the CSV written (one row per stage)\n");
  args.option("--case", case_path);
  args.option("--h", h);
  args.option("--iterations", iterations);
  args.option("--threads", threads);
  args.option("-o", csv_path);
  args.flag("--whole-surface", whole_surface);
  args.parse(argc, argv);
  if (!(h > 0)) args.fail("--h: a positive mesh size");
  if (iterations < 2) args.fail("--iterations: at least 2 (the first is not counted)");
  if (threads < 0) args.fail("--threads: a positive count (0: every core)");
  if (!std::filesystem::exists(case_path)) args.fail(case_path + ": no such case (run from the source tree, or give --case)");
  std::unique_ptr<tbb::global_control> control;
  if (threads > 0) control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  spdlog::set_level(spdlog::level::warn);

  const Bandwidth bandwidth = measure_bandwidth();
  std::printf("bandwidth: read %.1f GB/s, copy %.1f GB/s (read + written)\n", bandwidth.read, bandwidth.copy);

  // The shipped case at the benchmark suite's settings: h = hmax, hmin = h/10, outputs off.
  toml::table table = toml::parse_file(case_path);
  table["surface"].as_table()->insert_or_assign("h", h);
  table["remesh"].as_table()->insert_or_assign("hmax", h);
  table["remesh"].as_table()->insert_or_assign("hmin", h / 10);
  table["time"].as_table()->erase("final_time");
  table["time"].as_table()->insert_or_assign("iterations", iterations);
  if (whole_surface) table["time"].as_table()->insert_or_assign("narrow_band", false);
  table.erase("output");
  CaseConfig config = parse_case(table);
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  CaseSetup setup = setup_case(config);
  const EvolutionResult result = evolve(setup.mesh, model.model(), setup.options, {}, EvolutionHooks::quiet());
  const double nv = double(setup.mesh.n_vertices()), nf = double(setup.mesh.n_faces());

  auto median = [&](double StageTimes::*stage) {
    std::vector<double> ms;
    for (std::size_t k = 1; k < result.records.size(); ++k) ms.push_back(result.records[k].ms.*stage);  // not the first
    std::sort(ms.begin(), ms.end());
    return ms.empty() ? 0.0 : ms[ms.size() / 2];
  };
  const double measured[] = {median(&StageTimes::velocity), median(&StageTimes::distance), median(&StageTimes::advect),
                             median(&StageTimes::discretize), median(&StageTimes::remesh)};
  std::ofstream csv(csv_path);
  csv << "stage,faces,bytes,floor_ms,measured_ms,ratio,read_GBps,copy_GBps\n";
  std::printf("%s, h = %g: %.0f faces, %.0f vertices, median of iterations 2-%d\n", case_path.c_str(), h, nf, nv, iterations);
  std::printf("%-11s %9s %9s %11s %7s  %s\n", "stage", "MB", "floor ms", "measured ms", "ratio", "data");
  double floor_total = 0, measured_total = 0;
  const auto data = stage_data(nv, nf);
  for (std::size_t k = 0; k < data.size(); ++k) {
    const double floor_ms = data[k].bytes / (bandwidth.read * 1e9) * 1e3;
    floor_total += floor_ms;
    measured_total += measured[k];
    std::printf("%-11s %9.1f %9.2f %11.1f %7.0f  %s\n", data[k].stage, data[k].bytes * 1e-6, floor_ms, measured[k],
                measured[k] / floor_ms, data[k].arrays);
    csv << data[k].stage << ',' << nf << ',' << data[k].bytes << ',' << floor_ms << ',' << measured[k] << ','
        << measured[k] / floor_ms << ',' << bandwidth.read << ',' << bandwidth.copy << '\n';
  }
  std::printf("%-11s %9s %9.2f %11.1f %7.0f\n", "total", "", floor_total, measured_total, measured_total / floor_total);
  std::printf("-> %s\n", csv_path.c_str());
  return 0;
}
