// The soak, short: two overlapping caps go in and out once per period (conormal model
// with a periodic speed, bench/soak_case.hpp), splitting and merging twice per period, for a few
// hundred iterations at a coarse size. Every bound comes from an argument, not from this run's
// figures (docs/validation/drift.md has those): the exact area where it is known, give or take
// half an edge of front; the exact splits and merges; the quality goal; no memory
// growth of the size of a mesh.
#include "../bench/soak_case.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

using namespace bodyfit;

// Whether AddressSanitizer instruments this build (gcc says __SANITIZE_ADDRESS__, clang __has_feature).
#if defined(__SANITIZE_ADDRESS__)
#define BODYFIT_TEST_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define BODYFIT_TEST_UNDER_ASAN 1
#endif
#endif
#ifndef BODYFIT_TEST_UNDER_ASAN
#define BODYFIT_TEST_UNDER_ASAN 0
#endif

TEST_CASE("soak: the exact |G(0)| is the area of the union of the two caps") {
  // Independently of the bench's quadrature: cap 0, plus the rings about axis 0 outside it, each
  // counted for the part of it inside cap 1 (a closed form in the azimuth about axis 0).
  const soak::SoakCase c;
  const double a = c.cap_angle * std::numbers::pi / 180, d = c.separation * std::numbers::pi / 180;
  const int n = 200000;
  double area = 2 * std::numbers::pi * (1 - std::cos(a));
  const double step = d / n;  // rings from β = a to a + d: beyond it no point is in cap 1
  for (int i = 0; i < n; ++i) {
    const double beta = a + (i + 0.5) * step;
    const double threshold = (std::cos(a) - std::cos(beta) * std::cos(d)) / (std::sin(beta) * std::sin(d));
    area += 2 * std::sin(beta) * std::acos(std::clamp(threshold, -1.0, 1.0)) * step;
  }
  const soak::ExactArea exact(c);
  CHECK(exact.initial() == doctest::Approx(area).epsilon(1e-4));  // the bench's grid is 0.35°: second order
}

TEST_CASE("soak (short): two caps split and merge for 400 iterations, area, quality, faces and memory stay bounded") {
  soak::SoakCase c;
  c.h = 0.1;
  c.period = 4;  // Δt = 0.05: 80 steps per period, 5 periods
  c.iterations = 400;
  const soak::ExactArea exact(c);
  CaseConfig config = parse_case(toml::parse(c.toml()));
  LoadedModel model = load_model(config.model);
  configure_model(model, config.model_parameters);
  CaseSetup setup = setup_case(config);
  const long steps_per_period = std::lround(c.period / setup.options.dt);
  const std::size_t faces_start = setup.mesh.n_faces();
  // The exact G splits at S = −0.625 (t = 1.575 in each period of 4) and merges again at t = 2.425.
  std::vector<int> most_components(std::size_t(c.iterations / steps_per_period), 0);
  double worst_excess = -1e300, worst_error = 0, worst_quality = 1, worst_share = 0, rss_after_first_period = 0,
         rss_max = 0, longest_front = 0;
  std::size_t faces_min = SIZE_MAX, faces_max = 0;
  int last_components = 0;
  EvolutionHooks hooks = EvolutionHooks::quiet();
  hooks.on_iteration = [&](const SurfaceMesh& mesh, const IterationRecord& r, const RunState&) {
    // Where the exact |G| is known (the way in, and the ends of the periods), the cut resolves the
    // front to within half an edge: |G| within |∂G|·h/2 of it. (NaN on the way out: skipped.)
    const double error = std::abs(r.area - exact.at(r.time));
    if (std::isfinite(error)) {
      worst_error = std::max(worst_error, error);
      worst_excess = std::max(worst_excess, error - 0.5 * c.h * r.interface_length);
    }
    longest_front = std::max(longest_front, r.interface_length);
    worst_quality = std::min(worst_quality, r.min_quality);
    worst_share = std::max(worst_share, soak::share_below(mesh, 0.3));
    faces_min = std::min(faces_min, r.faces), faces_max = std::max(faces_max, r.faces);
    const std::size_t period = std::size_t((r.iteration - 1) / steps_per_period);
    if (period < most_components.size()) most_components[period] = std::max(most_components[period], r.components);
    last_components = r.components;
    if (r.iteration == steps_per_period) rss_after_first_period = soak::rss_mib();
    if (r.iteration > steps_per_period) rss_max = std::max(rss_max, soak::rss_mib());
  };
  const EvolutionResult result = evolve(setup.mesh, model.model(), setup.options, {}, hooks);
  MESSAGE("soak h = 0.1, " << result.iteration << " iterations: largest |area - exact| " << worst_error
                           << " (least margin to |dG| h/2: " << -worst_excess << "), worst quality " << worst_quality
                           << ", max share below 0.3 " << worst_share << ", faces " << faces_min << ".." << faces_max
                           << " (start " << faces_start << "), RSS " << rss_after_first_period << " -> max " << rss_max
                           << " MiB");
  CHECK(result.iteration == c.iterations);
  CHECK(worst_excess <= 0);
  for (std::size_t period = 0; period < most_components.size(); ++period) {
    INFO("period " << period + 1);
    CHECK(most_components[period] >= 2);  // it split
  }
  CHECK(last_components == 1);  // and merged again
  // The quality goal for the remesher's triangles.
  CHECK(worst_quality > 0.2);
  CHECK(worst_share <= 0.005);
  // The sphere's faces are set by hmax; the front adds or removes a strip of refinement along it,
  // a few faces per edge length of front.
  CHECK(double(faces_max) <= double(faces_start) + 4 * longest_front / c.h);
  CHECK(double(faces_min) >= double(faces_start) - 4 * longest_front / c.h);
  // A leak of one mesh per iteration (~3,000 faces, several hundred kB with OpenMesh's
  // connectivity) over the 320 iterations after the first period would exceed 8 MiB many times.
  // (Not under AddressSanitizer, whose quarantine holds freed blocks back by design: its RSS grows
  // by up to its quarantine size with no leak. LeakSanitizer checks leaks there instead.)
#if !BODYFIT_TEST_UNDER_ASAN
  CHECK(rss_max < rss_after_first_period + 8);
#endif
}
