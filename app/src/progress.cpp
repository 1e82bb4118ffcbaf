// The console lines of a run (progress.hpp).
#include <bodyfit/app/progress.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

namespace bodyfit {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  if (seconds < 10) return fmt::format("{:.1f} s", seconds);
  const long s = std::lround(seconds);
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

Progress::Progress(const EvolutionOptions& options, const RunState& start, ProgressOptions settings)
    : options_(options), start_(start), settings_(std::move(settings)), clock_start_(std::chrono::steady_clock::now()) {
  start_done_ = done(start.iteration, start.time);
}

double Progress::done(int iteration, double time) const {
  double share = 0;
  if (options_.max_iterations > 0) share = std::max(share, double(iteration) / double(options_.max_iterations));
  if (std::isfinite(options_.final_time) && options_.final_time > 0) share = std::max(share, time / options_.final_time);
  return std::clamp(share, 0.0, 1.0);
}

std::string Progress::position(int iteration, double time) const {
  const std::string& unit = settings_.time_unit;
  const std::string t = unit.empty() ? fmt::format("t = {:.5g}", time) : fmt::format("t = {:.5g} {}", time, unit);
  std::string where;
  if (options_.max_iterations > 0) where = fmt::format("{}/{}", iteration, options_.max_iterations);
  else where = fmt::format("n = {}", iteration);
  if (std::isfinite(options_.final_time))
    where += unit.empty() ? fmt::format(", {} of {:.5g}", t, options_.final_time)
                          : fmt::format(", {} of {:.5g} {}", t, options_.final_time, unit);
  else
    where += ", " + t;
  const double share = done(iteration, time);
  if (share <= 0) return "[" + where + "]";
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start_).count();
  const double progressed = share - start_done_;
  const std::string left = progressed > 0 ? format_duration(elapsed * (1 - share) / progressed) + " left" : "";
  return fmt::format("[{}, {:.0f} %{}]", where, 100 * share, left.empty() ? "" : ", " + left);
}

void Progress::iteration(const IterationRecord& r) {
  const std::string& length = settings_.length_unit;
  std::string state = fmt::format("|G| = {:.5g}{}  |∂G| = {:.5g}{}  faces {}  q_min {:.3f}", r.area,
                                  length.empty() ? "" : " " + length + "²", r.interface_length,
                                  length.empty() ? "" : " " + length, r.faces, r.min_quality);
  if (r.components != 1) state += fmt::format("  {} parts", r.components);
  if (r.substeps > 1) state += fmt::format("  {} sub-steps", r.substeps);
  if (r.rejections > 0) state += fmt::format("  {} rejected", r.rejections);
  std::string stages;
  if (settings_.verbose)
    stages = fmt::format("  ms: velocity {:.1f} distance {:.1f} advect {:.1f} cut {:.1f} remesh {:.1f}{} output {:.1f}",
                         r.ms.velocity, r.ms.distance, r.ms.advect, r.ms.discretize, r.ms.remesh,
                         r.ms.review > 0.05 ? fmt::format(" review {:.1f}", r.ms.review) : std::string(), r.ms.output);
  spdlog::info("{} {}{}", position(r.iteration, r.time), state, stages);
}

void Progress::summary(const EvolutionResult& result, const std::string& directory,
                       const std::vector<std::string>& files) const {
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start_).count();
  const int made = result.iteration - start_.iteration;
  const std::string& unit = settings_.time_unit;
  spdlog::info("{}: {} iteration{} in {} (t = {:.6g}{}), {}", result.reason == StopReason::Interrupted ? "interrupted" : "done",
               made, made == 1 ? "" : "s", format_duration(elapsed), result.time, unit.empty() ? "" : " " + unit,
               result.message);
  if (!files.empty()) spdlog::info("in {}: {}", directory, fmt::join(files, ", "));
}

}  // namespace bodyfit
