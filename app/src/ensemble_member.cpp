// One member of an ensemble: its case, its run, its files (ensemble.hpp).
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/model_guard.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <toml++/toml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace bodyfit {
namespace {

namespace fs = std::filesystem;

fs::path member_stem(const fs::path& outdir, std::size_t index) {
  return outdir / "members" / fmt::format("m{:06d}", index);
}

std::string with_extension(const fs::path& stem, const char* extension) { return stem.string() + extension; }

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
    out << "ignition = [" << number(r.x) << ", " << number(r.y) << "]\n";
    out << "burnt_area = " << number(r.burnt_area) << "\n";
    out << "final_time = " << number(r.final_time) << "\n";
    out << "iterations = " << r.iterations << "\n";
    out << "stop = " << quoted(r.stop) << "\n";
    out << "error = " << quoted(r.error) << "\n";
    out << "[parameters]\n";
    for (const auto& [key, value] : r.parameters) out << quoted(key) << " = " << number(value) << "\n";
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

/// The member's case and run; fills `record` (ok) or throws the member's error.
/// False when interrupted.
bool evolve_member(const EnsembleRun& run, const MemberScenario& s, const fs::path& work, const std::atomic<bool>* stop,
                   MemberRecord& record) {
  if (!s.ignition_found)
    throw InputError(fmt::format("no ignition point found in the ignition domain after {} draws (polygon and mask "
                                 "of [ensemble.ignition] do not overlap?)",
                                 run.spec.ignition.max_attempts));
  for (std::size_t k = 0; k < s.values.size(); ++k)
    if (std::isnan(s.values[k]))
      throw InputError(fmt::format("[ensemble.sample] \"{}\": no draw within [min, max] in 10000 attempts",
                                   run.spec.parameters[k].key));
  if (std::find(run.inject_failures.begin(), run.inject_failures.end(), s.index) != run.inject_failures.end())
    throw NumericalError("injected failure (--inject-failure, a test hook)");

  std::vector<std::string> overrides = run.overrides;
  overrides.insert(overrides.end(), s.overrides.begin(), s.overrides.end());
  overrides.push_back("output.vtu_every=0");
  overrides.push_back("output.png_every=0");
  // A member's raster is read back by the reduction only: the ESRI grid (+ .prj), and no perimeters.
  overrides.push_back("model.arrival.format=\"asc\"");
  overrides.push_back("model.perimeters.file=\"\"");
  CaseConfig config = read_case(run.case_file, overrides);
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters, case_surface_source(config));
  CaseSetup setup = setup_case(config);
  if (region_area(setup.mesh, kInside) <= 0)
    throw InputError(fmt::format("the ignition disk at ({}, {}) of radius {} covers no face of the surface (outside "
                                 "S, or smaller than its triangles)",
                                 s.x, s.y, run.domain.radius));
  setup.options.output_dir = work;
  setup.options.height_field = config.surface.kind == SurfaceSpec::Kind::Terrain;
  GuardedModel guarded(model.model(), 0);
  EvolutionHooks hooks = EvolutionHooks::quiet();
  hooks.stop = stop;
  const EvolutionResult result = evolve(setup.mesh, guarded, setup.options, {}, hooks);
  if (result.reason == StopReason::Interrupted) return false;
  if (result.reason == StopReason::Rejected) throw PluginError(result.message);
  record.burnt_area = region_area(setup.mesh, kInside);
  record.final_time = result.time;
  record.iterations = result.iteration;
  record.stop = result.message;
  const fs::path arrival = work / "arrival_time.asc";
  if (!fs::exists(arrival))
    throw InputError(fmt::format("model '{}' wrote no arrival_time.asc: an ensemble needs a model with an "
                                 "arrival-time raster (the fire model on a terrain)",
                                 config.model));
  const fs::path stem = member_stem(run.outdir, s.index);
  fs::rename(arrival, with_extension(stem, ".asc"));
  std::error_code ec;
  if (fs::exists(work / "arrival_time.prj")) fs::rename(work / "arrival_time.prj", with_extension(stem, ".prj"));
  else fs::remove(with_extension(stem, ".prj"), ec);
  record.ok = true;
  return true;
}

}  // namespace

fs::path member_record_path(const fs::path& outdir, std::size_t index) {
  return with_extension(member_stem(outdir, index), ".toml");
}

fs::path member_raster_path(const fs::path& outdir, std::size_t index) {
  return with_extension(member_stem(outdir, index), ".asc");
}

bool read_member_record(const fs::path& outdir, std::size_t index, MemberRecord& record) {
  const fs::path file = member_record_path(outdir, index);
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
  const toml::array* ignition = t["ignition"].as_array();
  if (!recorded || std::size_t(*recorded) != index || !status || !ignition || ignition->size() != 2) return false;
  record.index = index;
  record.ok = *status == "ok";
  record.x = (*ignition)[0].value<double>().value_or(NAN);
  record.y = (*ignition)[1].value<double>().value_or(NAN);
  record.burnt_area = t["burnt_area"].value<double>().value_or(NAN);
  record.final_time = t["final_time"].value<double>().value_or(NAN);
  record.iterations = int(t["iterations"].value<std::int64_t>().value_or(0));
  record.stop = t["stop"].value<std::string>().value_or("");
  record.error = t["error"].value<std::string>().value_or("");
  if (const toml::table* parameters = t["parameters"].as_table())
    for (auto&& [key, value] : *parameters)
      record.parameters.emplace_back(std::string(key.str()), value.value<double>().value_or(NAN));
  return !record.ok || fs::exists(member_raster_path(outdir, index), ec);
}

bool run_member(const EnsembleRun& run, std::size_t index, const std::atomic<bool>* stop) {
  const MemberScenario s = sample_member(run.spec, run.domain, index);
  MemberRecord record;
  record.index = index;
  record.x = s.x, record.y = s.y;
  for (std::size_t k = 0; k < s.values.size(); ++k) record.parameters.emplace_back(run.spec.parameters[k].key, s.values[k]);

  const fs::path work = with_extension(member_stem(run.outdir, index), ".work");
  std::error_code ec;
  fs::remove_all(work, ec);
  fs::create_directories(work, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the member's directory ({})", work.string(), ec.message()));
  const auto start = std::chrono::steady_clock::now();
  try {
    if (!evolve_member(run, s, work, stop, record)) {
      fs::remove_all(work, ec);
      return false;
    }
  } catch (const IoError&) {
    throw;  // the ensemble's directory, not the member
  } catch (const std::exception& e) {
    record.ok = false;
    record.error = fmt::format("{}: {}", error_kind(e), e.what());
  }
  write_record(member_record_path(run.outdir, index), record);
  fs::remove_all(work, ec);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (record.ok)
    spdlog::info("member {}: ignition ({:.1f}, {:.1f}), {} iterations, t = {}, |G| = {:.4g} ({:.1f} s)", index,
                 record.x, record.y, record.iterations, record.final_time, record.burnt_area, seconds);
  else
    spdlog::warn("member {} failed: {}", index, record.error);
  return true;
}

}  // namespace bodyfit
