// An ensemble's [ensemble] table and the sampling of its members (ensemble.hpp).
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/parameters.hpp>

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace bodyfit {
namespace {

// Streams of the hash: what a draw is for (a parameter's stream is a hash of its key, so adding a
// parameter to the case leaves the others' draws as they were).
// The placement's stream keeps the constant it was introduced with: the same seed draws the same points.
constexpr std::uint64_t kPlacementStream = 0x69676e6974696f6eULL;

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

std::uint64_t fnv1a(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : text) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

/// Uniform in [0, 1): the top 53 bits of the hash.
double uniform01(std::uint64_t seed, std::uint64_t index, std::uint64_t stream, std::uint64_t draw) {
  return double(ensemble_hash(seed, index, stream, draw) >> 11) * 0x1.0p-53;
}

SampledParameter read_sampled(const std::string& key, const toml::node& node) {
  const std::string section = "ensemble.sample.\"" + key + "\"";
  const toml::table* t = node.as_table();
  if (!t) throw InputError(fmt::format("{}[{}]: expected a table like {{dist = \"uniform\", min = 0, max = 1}}",
                                       location_of(node), section));
  if (key.find('.') == std::string::npos || key.starts_with("ensemble.") || key.starts_with("surface.") ||
      key.starts_with("region.") || key.starts_with("output."))
    throw InputError(fmt::format("{}[ensemble.sample] \"{}\": expected a key of [model], [time] or a stage (the "
                                 "surface and the region are the ensemble's own, the outputs its members' own)",
                                 location_of(node), key));
  Parameters p(*t, section);
  SampledParameter s;
  s.key = key;
  const std::string dist = p.choice("dist", "uniform", {"uniform", "normal", "lognormal", "choice"});
  if (dist == "choice") {
    // Values of any TOML kind (a wind height, a fuel model, a number), drawn with their weights.
    s.distribution = SampledParameter::Distribution::Choice;
    const toml::array* values = t->get_as<toml::array>("values");
    if (!values || values->empty())
      p.fail("values", "expected a non-empty array of the values to choose from, e.g. values = [\"midflame\", \"20ft\"]");
    p.accept("values");
    for (const toml::node& v : *values) {
      if (!v.is_string() && !v.is_number() && !v.is_boolean())
        p.fail("values", "expected strings, numbers or booleans");
      std::ostringstream text;
      v.visit([&](const auto& value) { text << value; });
      s.choices.push_back(text.str());
    }
    if (t->contains("weights")) {
      s.weights = p.numbers("weights", {}, values->size(), {.min = 0});
      double total = 0;
      for (double w : s.weights) total += w;
      if (!(total > 0) || !std::isfinite(total)) p.fail("weights", "expected weights ≥ 0 with a positive sum");
    }
  } else if (dist == "uniform") {
    s.distribution = SampledParameter::Distribution::Uniform;
    s.a = p.required_number("min");
    s.b = p.required_number("max");
    if (!(s.a <= s.b) || !std::isfinite(s.a) || !std::isfinite(s.b)) p.fail("max", "expected finite min ≤ max");
  } else {
    s.distribution = dist == "normal" ? SampledParameter::Distribution::Normal : SampledParameter::Distribution::LogNormal;
    s.a = p.required_number(dist == "normal" ? "mean" : "mu");
    s.b = p.required_number(dist == "normal" ? "sd" : "sigma", {.min = 0});
    s.min = p.number("min", s.min);
    s.max = p.number("max", s.max);
    if (!(s.min < s.max)) p.fail("max", "expected min < max");
  }
  p.reject_unknown();
  return s;
}

/// A number as TOML text that reads back exactly, and as a float ("5" would be an integer).
std::string toml_number(double v) {
  std::string text = fmt::format("{}", v);
  if (text.find_first_of(".en") == std::string::npos) text += ".0";
  return text;
}

bool on_footprint(const std::vector<PlanPolygon>& footprint, double x, double y) {
  if (footprint.empty()) return true;
  return std::any_of(footprint.begin(), footprint.end(),
                     [&](const PlanPolygon& p) { return signed_distance_to_polygon(p, x, y) < 0; });
}

bool mask_allows(const HeightGrid& mask, double x, double y) {
  if (mask.cols == 0) return true;
  const double c = std::floor((x - mask.x_origin) / mask.cell_size);
  const double s = std::floor((y - mask.y_origin) / mask.cell_size);  // rows from the south
  if (c < 0 || s < 0 || c >= double(mask.cols) || s >= double(mask.rows)) return false;
  const std::size_t row = mask.rows - 1 - std::size_t(s);
  const double value = mask.at(row, std::size_t(c));
  return std::isfinite(value) && value != mask.nodata && value > 0;
}

/// A standard normal draw (Box–Muller on two uniforms of the same attempt).
double standard_normal(std::uint64_t seed, std::uint64_t index, std::uint64_t stream, std::uint64_t attempt) {
  const double u1 = 1.0 - uniform01(seed, index, stream, 2 * attempt);  // (0, 1]
  const double u2 = uniform01(seed, index, stream, 2 * attempt + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace

std::uint64_t ensemble_hash(std::uint64_t seed, std::uint64_t index, std::uint64_t stream, std::uint64_t draw) {
  std::uint64_t h = splitmix64(seed);
  h = splitmix64(h ^ index);
  h = splitmix64(h ^ stream);
  return splitmix64(h ^ draw);
}

EnsembleSpec read_ensemble_spec(const std::filesystem::path& case_file, const std::vector<std::string>& overrides) {
  toml::table table = read_case_table(case_file, overrides);
  try {
    const toml::table* ensemble = table["ensemble"].as_table();
    Parameters p(ensemble, "ensemble");
    EnsembleSpec spec;
    spec.members = std::size_t(p.integer("members", 100, 1, 100000000));
    spec.seed = std::uint64_t(p.integer("seed", 1, 0));
    spec.percentiles = p.numbers("percentiles", spec.percentiles, std::nullopt, {.min = 0, .max = 100});
    if (const toml::table* region = p.table("region")) {
      Parameters r(*region, "ensemble.region");
      for (const auto& point : r.number_arrays("polygon", 2)) spec.region.polygon.push_back({point[0], point[1]});
      if (!spec.region.polygon.empty() && spec.region.polygon.size() < 3)
        r.fail("polygon", "expected at least 3 points [[x, y], ...]");
      spec.region.mask = r.path("mask", "");
      spec.region.radius = r.number("radius", 0, {.min = 0});
      spec.region.max_attempts = int(r.integer("max_attempts", spec.region.max_attempts, 1, 1000000000));
      r.reject_unknown();
    }
    if (const toml::table* sample = p.table("sample"))
      for (auto&& [key, node] : *sample) spec.parameters.push_back(read_sampled(std::string(key.str()), node));
    p.reject_unknown();
    return spec;
  } catch (const InputError& e) {
    if (std::string_view(e.what()).starts_with(case_file.string() + ":")) throw;
    throw file_error(case_file, e.what());
  }
}

PlacementDomain make_placement_domain(const std::filesystem::path& case_file, const std::vector<std::string>& overrides,
                                      const EnsembleSpec& spec) {
  PlacementDomain domain;
  domain.polygon = spec.region.polygon;
  domain.radius = spec.region.radius;
  const CaseConfig config = read_case(case_file, overrides);
  SurfaceMesh surface = make_case_surface(config);
  const BoundingBox box = bounding_box(surface);
  if (domain.polygon.empty())
    domain.polygon = {{box.min[0], box.min[1]}, {box.max[0], box.min[1]}, {box.max[0], box.max[1]}, {box.min[0], box.max[1]}};
  if (domain.radius == 0) domain.radius = 2 * edge_length_stats(surface).mean;
  if (config.surface.kind == SurfaceSpec::Kind::Terrain) {
    for (auto f : surface.faces()) surface.region(f) = kInside;
    domain.footprint = region_outline(surface);
  }
  domain.xmin = domain.xmax = domain.polygon[0][0];
  domain.ymin = domain.ymax = domain.polygon[0][1];
  for (const auto& p : domain.polygon) {
    domain.xmin = std::min(domain.xmin, p[0]), domain.xmax = std::max(domain.xmax, p[0]);
    domain.ymin = std::min(domain.ymin, p[1]), domain.ymax = std::max(domain.ymax, p[1]);
  }
  if (!spec.region.mask.empty()) domain.mask = read_raster(spec.region.mask);
  return domain;
}

MemberScenario sample_member(const EnsembleSpec& spec, const PlacementDomain& domain, std::size_t index) {
  MemberScenario s;
  s.index = index;
  for (int attempt = 0; attempt < spec.region.max_attempts; ++attempt) {
    const double x = domain.xmin + uniform01(spec.seed, index, kPlacementStream, 2 * std::uint64_t(attempt)) *
                                       (domain.xmax - domain.xmin);
    const double y = domain.ymin + uniform01(spec.seed, index, kPlacementStream, 2 * std::uint64_t(attempt) + 1) *
                                       (domain.ymax - domain.ymin);
    if (inside_ring(domain.polygon, x, y) && mask_allows(domain.mask, x, y) && on_footprint(domain.footprint, x, y)) {
      s.x = x, s.y = y;
      s.placed = true;
      break;
    }
  }
  s.overrides.push_back(fmt::format("region={{shape = \"disks\", centers = [[{}, {}]], radii = [{}]}}",
                                    toml_number(s.x), toml_number(s.y), toml_number(domain.radius)));
  for (const SampledParameter& p : spec.parameters) {
    const std::uint64_t stream = fnv1a(p.key);
    double value = std::numeric_limits<double>::quiet_NaN();
    if (p.distribution == SampledParameter::Distribution::Uniform) {
      value = p.a + uniform01(spec.seed, index, stream, 0) * (p.b - p.a);
    } else if (p.distribution == SampledParameter::Distribution::Choice) {
      std::vector<double> weights = p.weights.empty() ? std::vector<double>(p.choices.size(), 1.0) : p.weights;
      double total = 0;
      for (double w : weights) total += w;
      double u = uniform01(spec.seed, index, stream, 0) * total;
      std::size_t k = 0;
      while (k + 1 < weights.size() && u >= weights[k]) u -= weights[k++];
      s.values.push_back(double(k));
      s.overrides.push_back(p.key + "=" + p.choices[k]);
      continue;
    } else {
      // Truncated by redrawing: attempt k uses draws 2k and 2k + 1 of the parameter's stream.
      for (std::uint64_t attempt = 0; attempt < 10000; ++attempt) {
        const double z = standard_normal(spec.seed, index, stream, attempt);
        const double v = p.distribution == SampledParameter::Distribution::Normal ? p.a + p.b * z
                                                                                   : std::exp(p.a + p.b * z);
        if (v >= p.min && v <= p.max) {
          value = v;
          break;
        }
      }
    }
    s.values.push_back(value);
    s.overrides.push_back(p.key + "=" + toml_number(value));
  }
  return s;
}

}  // namespace bodyfit
