// One member of an ensemble: its case, its run, its files (ensemble.hpp).
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/app/model_files.hpp>
#include <bodyfit/app/run.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/model_guard.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <toml++/toml.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace bodyfit {
namespace {

/// Members whose grids cannot be combined: the case's error, which ends the ensemble (not a member
/// that failed on its own).
struct GridsDiffer : InputError {
  using InputError::InputError;
};

[[noreturn]] void grids_differ(const EnsembleRun& run, const std::string& name, const HeightGrid& frame,
                               std::size_t frame_index, const HeightGrid& grid, std::size_t index) {
  throw GridsDiffer(fmt::format("members {} and {}: their '{}' grids differ ({} × {} cells of {} at ({}, {}) against {} "
                                "× {} of {} at ({}, {})): the grid depends on a sampled parameter; give the model a "
                                "grid that does not (bodyfit plugins --describe {} names its parameters)",
                                frame_index, index, name, frame.cols, frame.rows, frame.cell_size, frame.x_origin,
                                frame.y_origin, grid.cols, grid.rows, grid.cell_size, grid.x_origin, grid.y_origin,
                                run.model));
}

/// The frame of the first member any process of the ensemble finished, kept in the output directory
/// (which the ranks of an MPI ensemble share), so that ranks whose members' grids differ stop after
/// their first members rather than at the reduction, after every member ran. The first process to
/// finish a member publishes its frame with link(), which fails when another did first.
void check_frame_of_other_processes(const EnsembleRun& run, const std::string& name, const HeightGrid& grid,
                                    std::size_t index) {
  const std::filesystem::path dir = run.outdir / "frames", file = dir / (name + ".frame");
  std::filesystem::create_directories(dir);
  const std::filesystem::path tmp = dir / fmt::format(".{}.m{:06d}.tmp", name, index);
  write_atomically(tmp, [&](std::ostream& out) {
    out << fmt::format("{} {} {:.17g} {:.17g} {:.17g} {}\n", grid.cols, grid.rows, grid.cell_size, grid.x_origin,
                       grid.y_origin, index);
  });
  const int linked = ::link(tmp.c_str(), file.c_str());
  const int error = errno;
  std::filesystem::remove(tmp);
  if (linked == 0) return;
  if (error != EEXIST) throw IoError(fmt::format("{}: {}", file.string(), std::strerror(error)));
  std::ifstream in(file);
  HeightGrid frame;
  std::size_t frame_index = 0;
  if (!(in >> frame.cols >> frame.rows >> frame.cell_size >> frame.x_origin >> frame.y_origin >> frame_index))
    throw IoError(fmt::format("{}:1: expected the frame of a grid (columns, rows, cell size, origin, member); "
                              "remove the file to start the frames over",
                              file.string()));
  if (!same_frame(frame, grid)) grids_differ(run, name, frame, frame_index, grid, index);
}

void check_same_frame(const EnsembleRun& run, const std::string& name, const HeightGrid& grid, std::size_t index) {
  std::lock_guard lock(run.frames->mutex);
  auto [it, first] = run.frames->first.try_emplace(name, grid, index);
  if (first) {
    it->second.first.heights.clear();  // the frame only
    check_frame_of_other_processes(run, name, grid, index);
    return;
  }
  const HeightGrid& frame = it->second.first;
  if (!same_frame(frame, grid)) grids_differ(run, name, frame, it->second.second, grid, index);
}

namespace fs = std::filesystem;

fs::path member_stem(const fs::path& outdir, std::size_t index) {
  return outdir / "members" / fmt::format("m{:06d}", index);
}

std::string with_extension(const fs::path& stem, const std::string& extension) { return stem.string() + extension; }

std::string quoted(const std::string& text) {
  std::ostringstream out;
  out << toml::value<std::string>(text);
  return out.str();
}

/// A number that reads back exactly (toml++ parses "inf" and "nan" too).
std::string number(double v) {
  std::string text = fmt::format("{}", v);
  if (text.find_first_of(".en") == std::string::npos) text += ".0";
  return text;
}

void write_record(const fs::path& file, const MemberRecord& r) {
  write_atomically(file, [&](std::ostream& out) {
    out << "# bodyfit ensemble member " << r.index << " (written last: the member is complete)\n";
    out << "index = " << r.index << "\n";
    out << "status = " << (r.ok ? "\"ok\"" : "\"failed\"") << "\n";
    out << "region = [" << number(r.x) << ", " << number(r.y) << "]\n";
    out << "final_time = " << number(r.final_time) << "\n";
    out << "iterations = " << r.iterations << "\n";
    out << "stop = " << quoted(r.stop) << "\n";
    out << "error = " << quoted(r.error) << "\n";
    out << "[parameters]\n";
    for (const auto& [key, value] : r.parameters) out << quoted(key) << " = " << number(value) << "\n";
    out << "[values]\n";
    for (const auto& [key, value] : r.values) out << quoted(key) << " = " << number(value) << "\n";
  });
}

const char* error_kind(const std::exception& e) {
  switch (exit_code_of(e)) {
    case ExitCode::Input: return "input error";
    case ExitCode::Plugin: return "model error";
    case ExitCode::Numerical: return "numerical error";
    case ExitCode::Io: return "output error";
    default: return "internal error";
  }
}

/// The member's case: the user's overrides, then the member's own, then no per-state files.
CaseConfig member_case(const EnsembleRun& run, const MemberScenario& s) {
  std::vector<std::string> overrides = run.overrides;
  overrides.insert(overrides.end(), s.overrides.begin(), s.overrides.end());
  overrides.push_back("output.vtu_every=0");
  overrides.push_back("output.png_every=0");
  return read_case(run.case_file, overrides);
}

/// The member's run; fills `record` (ok) and writes its grids, or throws the member's error.
/// False when interrupted.
bool evolve_member(const EnsembleRun& run, const MemberScenario& s, const std::atomic<bool>* stop,
                   MemberRecord& record) {
  if (!s.placed)
    throw InputError(fmt::format("no point found for G(0) after {} draws (polygon and mask of [ensemble.region] do "
                                 "not overlap?)",
                                 run.spec.region.max_attempts));
  for (std::size_t k = 0; k < s.values.size(); ++k)
    if (std::isnan(s.values[k]))
      throw InputError(fmt::format("[ensemble.sample] \"{}\": no draw within [min, max] in 10000 attempts",
                                   run.spec.parameters[k].key));
  if (std::find(run.inject_failures.begin(), run.inject_failures.end(), s.index) != run.inject_failures.end())
    throw NumericalError("injected failure (--inject-failure, a test hook)");

  Run member(member_case(run, s), {});  // no files of its own: its grids come to the ensemble
  if (region_area(member.mesh(), kInside) <= 0)
    throw InputError(fmt::format("G(0), the disk at ({}, {}) of radius {}, covers no face of the surface (outside "
                                 "S, or smaller than its triangles)",
                                 s.x, s.y, run.domain.radius));
  KeptOutputs kept(member.model()->outputs(), std::string(member.model()->name()));
  EvolutionHooks hooks = EvolutionHooks::quiet();
  hooks.stop = stop;
  hooks.outputs = &kept;
  const EvolutionResult result = member.evolve({}, hooks);
  if (result.reason == StopReason::Interrupted) return false;
  if (result.reason == StopReason::Rejected) throw PluginError(result.message);
  record.final_time = result.time;
  record.iterations = result.iteration;
  record.stop = result.message;
  for (const OutputDecl& d : run.values)
    if (auto it = kept.values().find(d.name); it != kept.values().end()) record.values.emplace_back(d.name, it->second);
  for (const OutputDecl& d : run.combined) {
    auto it = kept.grids().find(d.name);
    if (it == kept.grids().end())
      throw PluginError(fmt::format("model '{}' gave no '{}' grid at the end of the run: an ensemble combines the "
                                    "grids a model declares, and this run gave none",
                                    run.model, d.name));
    const HeightGrid raster = to_raster(it->second);
    check_same_frame(run, d.name, raster, s.index);
    write_raster(member_grid_path(run.outdir, s.index, d.name), raster, raster_metadata(it->second, d.unit));
  }
  record.ok = true;
  return true;
}

}  // namespace

fs::path member_record_path(const fs::path& outdir, std::size_t index) {
  return with_extension(member_stem(outdir, index), ".toml");
}

fs::path member_grid_path(const fs::path& outdir, std::size_t index, std::string_view name) {
  return with_extension(member_stem(outdir, index), fmt::format(".{}.asc", name));
}

bool read_member_record(const EnsembleRun& run, std::size_t index, MemberRecord& record) {
  const fs::path file = member_record_path(run.outdir, index);
  std::error_code ec;
  if (!fs::exists(file, ec)) return false;
  toml::table t;
  try {
    t = toml::parse_file(file.string());
  } catch (const toml::parse_error&) {
    return false;  // not ours, or damaged: the member runs again
  }
  record = MemberRecord{};
  const auto recorded = t["index"].value<std::int64_t>();
  const auto status = t["status"].value<std::string>();
  const toml::array* region = t["region"].as_array();
  if (!recorded || std::size_t(*recorded) != index || !status || !region || region->size() != 2) return false;
  record.index = index;
  record.ok = *status == "ok";
  record.x = (*region)[0].value<double>().value_or(NAN);
  record.y = (*region)[1].value<double>().value_or(NAN);
  record.final_time = t["final_time"].value<double>().value_or(NAN);
  record.iterations = int(t["iterations"].value<std::int64_t>().value_or(0));
  record.stop = t["stop"].value<std::string>().value_or("");
  record.error = t["error"].value<std::string>().value_or("");
  for (const char* table : {"parameters", "values"})
    if (const toml::table* entries = t[table].as_table())
      for (auto&& [key, value] : *entries)
        (std::string_view(table) == "values" ? record.values : record.parameters)
            .emplace_back(std::string(key.str()), value.value<double>().value_or(NAN));
  if (!record.ok) return true;
  for (const OutputDecl& d : run.combined)
    if (!fs::exists(member_grid_path(run.outdir, index, d.name), ec)) return false;
  return true;
}

void check_member_case(EnsembleRun& run) {
  const MemberScenario s = sample_member(run.spec, run.domain, 0);
  try {
    const CaseConfig config = member_case(run, s);
    const LoadedModel model = load_case_model(config);
    run.model = config.model;
    for (const OutputDecl& d : model->outputs()) {
      if (d.kind == OutputDecl::Kind::Grid && !d.ensemble.empty()) run.combined.push_back(d);
      if (d.kind == OutputDecl::Kind::Value) run.values.push_back(d);
    }
  } catch (const InputError& e) {
    std::vector<std::string> keys;
    for (const SampledParameter& p : run.spec.parameters) keys.push_back(p.key);
    throw InputError(fmt::format("the case of member 0 (with its sampled {}) is refused: {}",
                                 keys.empty() ? std::string("region") : fmt::format("{}", fmt::join(keys, ", ")),
                                 e.what()));
  }
  if (run.combined.empty())
    throw InputError(fmt::format("{}: model '{}' declares no grid output an ensemble combines: there is nothing to "
                                 "reduce (bodyfit plugins --describe {})",
                                 run.case_file.string(), run.model, run.model));
}

bool run_member(const EnsembleRun& run, std::size_t index, const std::atomic<bool>* stop) {
  const MemberScenario s = sample_member(run.spec, run.domain, index);
  MemberRecord record;
  record.index = index;
  record.x = s.x, record.y = s.y;
  for (std::size_t k = 0; k < s.values.size(); ++k) record.parameters.emplace_back(run.spec.parameters[k].key, s.values[k]);

  const auto start = std::chrono::steady_clock::now();
  try {
    if (!evolve_member(run, s, stop, record)) return false;
  } catch (const IoError&) {
    throw;  // the ensemble's directory, not the member
  } catch (const GridsDiffer&) {
    throw;  // the case, not the member
  } catch (const std::exception& e) {
    record.ok = false;
    record.error = fmt::format("{}: {}", error_kind(e), e.what());
  }
  write_record(member_record_path(run.outdir, index), record);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (record.ok)
    spdlog::info("member {}: G(0) at ({:.1f}, {:.1f}), {} iterations, t = {} ({:.1f} s)", index, record.x, record.y,
                 record.iterations, record.final_time, seconds);
  else
    spdlog::warn("member {} failed: {}", index, record.error);
  return true;
}

}  // namespace bodyfit
