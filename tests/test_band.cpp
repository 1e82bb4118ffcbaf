// The evolution near the front only (EvolutionOptions::narrow_band): d^n measured in a band that
// holds what a step reads, the advection tracing only the vertices the front can reach. Against
// the whole-surface computation: the same distances inside the band, the same fronts; a front that
// speeds up widens the band; a [distance] narrow_band too narrow is refused; a model that couples
// every vertex (smoothing) gets d on the whole surface.
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/distance.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/model_guard.hpp>
#include <bodyfit/projection.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <map>

using namespace bodyfit;

namespace {

const char* kCap = R"(
[surface]
generator = "sphere"
h = 0.1
[region]
shape = "cap"
axis = [0, 0, 1]
angle = 45
[model]
name = "conormal"
[time]
cfl = 0.5
final_time = 0.3
[remesh]
hmax = 0.1
)";

/// V = v(t)·n_Σ with v = 1, then `fast` from `switch_time` on; with `smoothing`, v is smoothed over
/// S first (StepContext::smooth couples every vertex). Records the largest |d| the first and the
/// last compute of each iteration are given.
class Conormal final : public VelocityModel {
 public:
  Conormal(double fast, double switch_time, bool smoothing) : fast_(fast), switch_(switch_time), smoothing_(smoothing) {}
  std::string_view name() const override { return "test conormal"; }
  void configure(Parameters&) override {}
  VelocityField compute(const StepContext& context) override {
    const std::size_t n = context.mesh().n_vertices();
    ScalarField speed(n, context.time() >= switch_ - 1e-12 ? fast_ : 1.0);
    if (smoothing_) speed = context.smooth(speed, 0.05);
    double largest = 0;
    for (double d : context.distance()) largest = std::max(largest, std::abs(d));
    largest_d.emplace(context.iteration(), largest);
    last_largest_d[context.iteration()] = largest;
    return VelocityField::normal(std::move(speed));
  }
  std::map<int, double> largest_d, last_largest_d;

 private:
  double fast_, switch_;
  bool smoothing_;
};

struct Run {
  EvolutionResult result;
  std::map<int, double> largest_d, last_largest_d;
};

Run run_cap(bool narrow_band, double fast = 1.0, double switch_time = 0.0, bool smoothing = false,
            double distance_band = INFINITY, double max_cfl = 0) {
  CaseSetup setup = setup_case(parse_case(toml::parse(kCap)));
  setup.options.narrow_band = narrow_band;
  setup.options.max_cfl = max_cfl;
  setup.options.distance.narrow_band = distance_band;
  Conormal model(fast, switch_time, smoothing);
  Run out;
  out.result = evolve(setup.mesh, model, setup.options, {}, EvolutionHooks::quiet());
  out.largest_d = model.largest_d;
  out.last_largest_d = model.last_largest_d;
  return out;
}

/// The fronts of two runs: the same states up to rounding (the band's advection sums a vertex's
/// gradient in another order than the whole surface's).
void check_same_fronts(const EvolutionResult& banded, const EvolutionResult& whole) {
  REQUIRE(banded.records.size() == whole.records.size());
  for (std::size_t k = 0; k < whole.records.size(); ++k) {
    CAPTURE(k);
    CHECK(banded.records[k].faces == whole.records[k].faces);
    CHECK(banded.records[k].area == doctest::Approx(whole.records[k].area).epsilon(1e-12));
    CHECK(banded.records[k].interface_length == doctest::Approx(whole.records[k].interface_length).epsilon(1e-12));
  }
  REQUIRE(banded.final_distance.size() == whole.final_distance.size());
  double worst = 0;
  for (std::size_t v = 0; v < whole.final_distance.size(); ++v)
    worst = std::max(worst, std::abs(banded.final_distance[v] - whole.final_distance[v]));
  CHECK(worst < 1e-12);  // the final state's d is measured on the whole surface in both
}

}  // namespace

TEST_CASE("d in a band: within its width the whole surface's distance, bit for bit, and beyond it the sign") {
  SurfaceMesh mesh = make_sphere({.faces = 20000});
  ScalarField phi(mesh.n_vertices());
  for (auto v : mesh.vertices()) phi[v.idx()] = mesh.point(v)[2] - 0.4 + 0.1 * mesh.point(v)[0];
  discretize(mesh, phi, {});
  for (bool curved : {false, true}) {
    CAPTURE(curved);
    DistanceOptions whole_options{.curved_interface = curved, .front_curvature = curved};
    const ScalarField whole = signed_distance_to_region(mesh, whole_options);
    DistanceOptions band_options = whole_options;
    band_options.narrow_band = 0.3;
    const ScalarField band = signed_distance_to_region(mesh, band_options);
    std::size_t inside = 0;
    for (std::size_t v = 0; v < whole.size(); ++v) {
      CHECK(std::signbit(band[v]) == std::signbit(whole[v]));
      if (std::abs(whole[v]) <= 0.3) {
        ++inside;
        CHECK(band[v] == whole[v]);
      } else {
        CHECK(std::isinf(band[v]));
      }
    }
    CHECK(inside > 1000);
    CHECK(inside < whole.size() / 2);
  }
}

TEST_CASE("a run in a band gives the whole surface's fronts, and its model sees d only within the band") {
  const Run banded = run_cap(true), whole = run_cap(false);
  check_same_fronts(banded.result, whole.result);
  // Iteration 0 measures d on the whole surface (nothing sized the band yet); from then on it is
  // banded: 1.5 × (2·reach + 6 longest edges) ≈ 1.2 here, where d reaches 2.4 on the whole sphere.
  REQUIRE(banded.largest_d.size() == whole.largest_d.size());
  CHECK(banded.largest_d.at(0) == whole.largest_d.at(0));
  for (int n = 1; n < int(whole.largest_d.size()); ++n) {
    CAPTURE(n);
    CHECK(whole.largest_d.at(n) > 2.0);
    CHECK(banded.largest_d.at(n) < 0.7 * whole.largest_d.at(n));
  }
}

TEST_CASE("CFL sub-steps on a banded d: the whole surface's fronts") {
  // Each step of 0.05 is made of sub-steps moving the front at most max_cfl·h ≈ 0.025.
  const Run banded = run_cap(true, 1.0, 0.0, false, INFINITY, 0.25), whole = run_cap(false, 1.0, 0.0, false, INFINITY, 0.25);
  check_same_fronts(banded.result, whole.result);
  for (const auto& record : banded.result.records)
    if (record.iteration > 0) CHECK(record.substeps >= 2);
  CHECK(banded.largest_d.at(2) < 0.7 * whole.largest_d.at(2));
}

TEST_CASE("a front that speeds up 8×: the band is found too narrow, widened, and the front is the whole surface's") {
  // From t = 0.1 the step moves the front 0.4 = 4 edges: twice that plus 6 edges is beyond the
  // band the steps at unit speed sized (a band left as it was would stop the traces at its edge).
  const Run banded = run_cap(true, 8.0, 0.1), whole = run_cap(false, 8.0, 0.1);
  check_same_fronts(banded.result, whole.result);
  // Iteration 2 (t = 0.1) computes V on the band of the slow steps, finds it too narrow, measures
  // d again in a wider band and computes V again; the next steps' bands stay wide.
  CHECK(banded.last_largest_d.at(2) > 1.3 * banded.largest_d.at(2));
  CHECK(banded.largest_d.at(3) > 1.3 * banded.largest_d.at(2));
}

TEST_CASE("[distance] narrow_band narrower than a step reads is refused, naming the width the step needs") {
  CHECK_THROWS_WITH_AS(run_cap(true, 1.0, 0.0, false, 0.3), doctest::Contains("[distance] narrow_band = 0.3"),
                       InputError);
  // Wide enough: honoured, the same fronts.
  check_same_fronts(run_cap(true, 1.0, 0.0, false, 1.5).result, run_cap(false, 1.0, 0.0, false, 1.5).result);
}

TEST_CASE("a model that smooths over S is given d on the whole surface: the whole-surface run, bit for bit") {
  const Run banded = run_cap(true, 1.0, 0.0, true), whole = run_cap(false, 1.0, 0.0, true);
  REQUIRE(banded.result.records.size() == whole.result.records.size());
  for (std::size_t k = 0; k < whole.result.records.size(); ++k) {
    CAPTURE(k);
    CHECK(banded.result.records[k].area == whole.result.records[k].area);
    CHECK(banded.result.records[k].interface_length == whole.result.records[k].interface_length);
  }
  CHECK(banded.largest_d == whole.largest_d);
}

namespace {

const char* kTerrainDisk = R"(
[surface]
generator = "terrain"
extent = 40000.0
h = 500.0
seed = 7
max_height = 1500.0
feature_size = 3000.0
[region]
shape = "disks"
centers = [[20000.0, 20000.0]]
radii = [2000.0]
[model]
name = "conormal"
[time]
dt = 300.0
iterations = 4
)";

/// V = n_Σ; records, for each banded state's compute, whether band_vertices() is d's band and its
/// ring, and whether surface_normals() holds S's smooth normal there (bit for bit) and 0 beyond.
class BandProbe final : public VelocityModel {
 public:
  explicit BandProbe(const ReferenceSurface& surface) : surface_(surface) {}
  std::string_view name() const override { return "band probe"; }
  void configure(Parameters&) override {}
  VelocityField compute(const StepContext& context) override {
    const SurfaceMesh& mesh = context.mesh();
    const ScalarField& d = context.distance();
    const std::span<const int> band = context.band_vertices();
    if (context.active_vertices().empty() && !band.empty()) {
      ++banded_states;
      double width = 0;
      for (double value : d) width = std::max(width, std::abs(value));
      std::vector<char> expected(mesh.n_vertices(), 0);
      for (auto v : mesh.vertices())
        if (std::abs(d[v.idx()]) < width) {
          expected[v.idx()] = 1;
          for (auto w : mesh.vv_range(v)) expected[w.idx()] = 1;
        }
      std::vector<int> listed;
      for (std::size_t v = 0; v < expected.size(); ++v)
        if (expected[v]) listed.push_back(int(v));
      band_is_d_band = band_is_d_band && std::equal(band.begin(), band.end(), listed.begin(), listed.end());
      smaller_than_mesh = smaller_than_mesh && band.size() < mesh.n_vertices() / 2;
      const VectorField& normals = context.surface_normals();
      std::vector<char> in_band(mesh.n_vertices(), 0);
      for (int v : band) {
        in_band[std::size_t(v)] = 1;
        normals_exact = normals_exact && normals[std::size_t(v)] == surface_.smooth_normal(mesh.point(VertexHandle(v)));
      }
      for (auto v : mesh.vertices())
        if (!in_band[v.idx()]) zero_beyond = zero_beyond && normals[v.idx()] == Vec3(0, 0, 0);
    }
    VectorField velocity = context.conormal();
    return VelocityField::tangential(std::move(velocity));
  }
  int banded_states = 0;
  bool band_is_d_band = true, smaller_than_mesh = true, normals_exact = true, zero_beyond = true;

 private:
  const ReferenceSurface& surface_;
};

}  // namespace

TEST_CASE("in a banded state, band_vertices() is d's band and its ring, and surface_normals() S's normals there") {
  CaseSetup setup = setup_case(parse_case(toml::parse(kTerrainDisk)));
  auto surface = std::make_shared<ReferenceSurface>(setup.mesh);
  setup.options.remesh.reference = surface;
  setup.options.narrow_band = true;
  BandProbe probe(*surface);
  evolve(setup.mesh, probe, setup.options, {}, EvolutionHooks::quiet());
  CHECK(probe.banded_states >= 3);
  CHECK(probe.band_is_d_band);
  CHECK(probe.smaller_than_mesh);
  CHECK(probe.normals_exact);  // each vertex's own search: the same normal whichever are asked for
  CHECK(probe.zero_beyond);
  // A plugin built before ABI 3.3 may read S's normals anywhere: d on the whole surface, no band.
  for (std::uint32_t minor : {2u, 3u}) {
    CAPTURE(minor);
    CaseSetup again = setup_case(parse_case(toml::parse(kTerrainDisk)));
    again.options.remesh.reference = surface;
    again.options.narrow_band = true;
    BandProbe older(*surface);
    GuardedModel guarded(older, 0, (3u << 16) | minor);
    evolve(again.mesh, guarded, again.options, {}, EvolutionHooks::quiet());
    CHECK(older.banded_states == (minor == 2 ? 0 : probe.banded_states));
  }
}
