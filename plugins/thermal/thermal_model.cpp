// The thermal shape-optimisation model (paper §4.4) as a bodyfit plugin. S = ∂Ω is the skin of a
// part; G ⊂ S is held at temperature 0 through the Robin coefficient h_ε(d_G). The model moves G
// along a descent direction of the merit M(G) = j(u) + ℓ|G| (+ an augmented Lagrangian of a target
// area), j the case's objective (descent.hpp, objective.hpp; docs/reference/thermal_model.md):
//
//   compute(T^n)   tetrahedralise Ω (TetGen, S kept), solve the state u and the adjoint p, w = −(1/ε²)
//                  h′(d/ε) u p on S, then the descent normal speed v: (M + α²K) v = −(M w + ℓ_eff b_Σ),
//                  zero on Γ_N, normalised to max |v| = 1. On T⁰ it also measures the noise of j:
//                  j of the same G on a second surface mesh (a full remesh).
//   nuclei(T^n)    with [model.nucleation], every k-th state: disks of G where the topological
//                  sensitivity 4γup is most negative (nucleation.hpp), when they lower the merit.
//   review(T^{n+1}) M on the candidate; the sufficient-decrease test, the next Δt and the stops of
//                  Descent. The candidate's solution serves the next compute().
//   state          every accepted state's j, |G| and slope, λ, μ, the noise, ε and α as resolved, the
//                  bounds on Δt.
#include "box_field.hpp"
#include "descent.hpp"
#include "fixed_volume.hpp"
#include "nucleation.hpp"
#include "objective.hpp"
#include "shape_derivative.hpp"
#include "sharp_problem.hpp"
#include "smoothing.hpp"
#include "surface_check.hpp"
#include "surface_transfer.hpp"
#include "thermal_fem.hpp"
#include "volume_mesh.hpp"
#include "volume_vtu.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/distance.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/velocity_model.hpp>

#include <Eigen/SparseCholesky>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>

namespace bodyfit::thermal {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// Everything computed on one state (T^n or a candidate): its volume mesh, u, p and J.
struct Evaluation {
  int iteration = -1;   ///< the state it belongs to
  VolumeMesh volume;    ///< its own volume mesh (volume_mesh = "remeshed"; empty with "fixed")
  const VolumeMesh* solved_on = nullptr;  ///< the volume mesh of `solution`
  ThermalSolution solution;
  ThermalObjective objective;  ///< density at the state's vertices
  double interface_length = 0;  ///< |Σ| = ∫_Σ dℓ
  double ms_tetrahedralize = 0;
  std::vector<Vec3> sample_points;   ///< the boundary vertices of the volume mesh
  std::vector<double> band_weights;  ///< ∂T_ε/∂d at sample_points (shape_derivative.hpp)
  ScalarField u_surface, p_surface;  ///< u and p at the state's vertices
  ScalarField sensitivity;  ///< g = 4γup: J's change per unit radius of a new disk of G (nucleation.hpp)
  ScalarField speed;        ///< the descent speed v computed on this state (empty until then)
  double slope = 0;         ///< M′(v)
  double unit_slope = 0;    ///< M′(v / max |v|): the stationarity measure
  double area_rate = 0;     ///< ∫_Σ v = d|G|/dt along v
  double ms_direction = 0;  ///< its H¹ solve
};

class ThermalModel final : public VelocityModel {
 public:
  std::string_view name() const override { return "thermal"; }
  std::string_view version() const override { return "2.0"; }
  std::string_view description() const override {
    return "shape optimisation of the region G of a part's skin held at temperature 0: descent of "
           "J = j(u) + ell*|G| (mean or L^q-maximum temperature, a region's mean, the dissipation), with an "
           "optional target area and topological nucleation (paper §4.4; TetGen + P1 FEM + CHOLMOD)";
  }

  std::vector<ParameterDecl> parameters() const override {
    const Range positive{.min = 0, .min_exclusive = true};
    const std::vector<std::string> objectives{"mean_temperature", "max_temperature", "region_mean", "dissipation"};
    return {
        ParameterDecl::number("ell", "temperature/area", "weight ℓ of the area |G| in J").fallback(0.01).at_least(0),
        ParameterDecl::choice("objective", objectives, "the functional j(u) of J = j + ℓ|G|, or a table {kind, "
                                                       "exponent, boxes}")
            .fallback("mean_temperature"),
        ParameterDecl::choice("objective.kind", objectives, "see objective").fallback("mean_temperature"),
        ParameterDecl::number("objective.exponent", "1", "q of max_temperature: j = ((1/|Ω|)∫u^q)^(1/q)")
            .fallback(8.0)
            .at_least(1),
        ParameterDecl::points("objective.boxes", 6, "length",
                              "region_mean: [xmin, ymin, zmin, xmax, ymax, zmax]: j is the mean of u over the "
                              "tetrahedra whose centroid is in a box"),
        ParameterDecl::number("area.target", "area", "hold |G| to this area (augmented Lagrangian); 0 < target < |S|")
            .positive(),
        ParameterDecl::number("area.fraction", "1", "the target as a fraction of |S| (instead of area.target)")
            .within({.min = 0, .max = 1, .min_exclusive = true, .max_exclusive = true}),
        ParameterDecl::number("area.penalty", "1", "μ = penalty·|J⁰|/A²: the quadratic term of the augmented "
                                                   "Lagrangian")
            .fallback(10.0)
            .positive(),
        ParameterDecl::integer("area.update_every", "steps", "accepted steps between updates λ ← λ + μ(|G| − A)")
            .fallback(5)
            .within({.min = 1, .max = 1000000}),
        ParameterDecl::number("area.tolerance", "1", "a stationary stop needs ||G| − A| ≤ this × A").fallback(0.005).positive(),
        ParameterDecl::number("epsilon", "length", "half-width ε of the smoothed Dirichlet band")
            .computed("3 × the mean edge of T^0")
            .positive(),
        ParameterDecl::number("epsilon_final", "length", "ε continuation: when the descent stops, ε ← max(factor·ε, "
                                                         "epsilon_final) and it goes on, until ε = epsilon_final")
            .computed("min(epsilon, the mean edge h of T^0)")
            .positive(),
        ParameterDecl::number("continuation_factor", "1", "see epsilon_final").fallback(0.5).within(
            {.min = 0, .max = 1, .min_exclusive = true, .max_exclusive = true}),
        ParameterDecl::number("alpha", "h", "H¹ regularisation length of the velocity, in mean edges h").fallback(2.0).at_least(0),
        ParameterDecl::number("conductivity", "", "γ > 0, or a table {value, boxes}").fallback(1.0).within(positive),
        ParameterDecl::number("conductivity.value", "", "γ outside the boxes").fallback(1.0).within(positive),
        ParameterDecl::points("conductivity.boxes", 7, "", "[xmin, ymin, zmin, xmax, ymax, zmax, γ]: γ inside each box"),
        ParameterDecl::number("source", "", "heat source f, or a table {value, boxes}").fallback(1.0),
        ParameterDecl::number("source.value", "", "f outside the boxes").fallback(1.0),
        ParameterDecl::points("source.boxes", 7, "", "[xmin, ymin, zmin, xmax, ymax, zmax, f]: f inside each box"),
        ParameterDecl::points("neumann.boxes", 7, "",
                              "Γ_N: surface faces whose centroid is in a box [xmin, ymin, zmin, xmax, ymax, zmax, g]; G "
                              "may not go there"),
        ParameterDecl::number("neumann.flux", "", "heat flux g on Γ_N where no box value applies").fallback(0.0),
        ParameterDecl::number("radius_edge", "1", "TetGen quality bound -q (radius-edge ratio)").fallback(1.2).at_least(1),
        ParameterDecl::number("volume_factor", "1", "TetGen volume bound -a as a multiple of the regular tetrahedron of "
                                                    "edge h (0: none)")
            .fallback(0.0)
            .at_least(0),
        ParameterDecl::choice("solver", {"conjugate_gradient", "cholmod_supernodal", "cholmod_simplicial", "eigen_simplicial"},
                              "conjugate_gradient (IC-preconditioned; falls back to CHOLMOD) or a direct solver")
            .fallback("conjugate_gradient"),
        ParameterDecl::number("armijo", "1", "sufficient decrease: M(new) ≤ M + armijo·Δt·M′(v) + noise·|M|, else the "
                                             "step is rejected")
            .fallback(1e-4)
            .within({.min = 0, .max = 1, .max_exclusive = true}),
        ParameterDecl::number("noise", "1", "relative increase of J tolerated for the remeshing and tetrahedralisation "
                                            "noise of the discrete J")
            .computed("twice the measured relative scatter of J between two meshes of G⁰")
            .within({.min = 0, .max = 1}),
        ParameterDecl::number("min_step_factor", "1", "a step whose front motion Δt·max|v| is below this × the case's Δt "
                                                      "and still raises J is taken anyway (a jump of the discretisation, "
                                                      "not an ascent)")
            .fallback(0.0625)
            .within({.min = 0, .max = 1}),
        ParameterDecl::number("grow", "1", "Δt is multiplied by this after a step accepted at its first attempt")
            .fallback(1.2)
            .at_least(1),
        ParameterDecl::number("max_dt_factor", "1", "cap on Δt, as a multiple of the case's Δt (the front's motion "
                                                    "Δt·max|v| is bounded apart, by h and ε/2)")
            .fallback(100.0)
            .at_least(1),
        ParameterDecl::number("stationarity", "1", "stop when |J′(v/max|v|)| falls to this fraction of its value on the "
                                                   "stage's first state (0: never)")
            .fallback(0.005)
            .within({.min = 0, .max = 1}),
        ParameterDecl::number("tolerance", "1", "stalled when the best J improves by less than this (relative; at least "
                                                "the noise) over `patience` accepted steps")
            .fallback(1e-3)
            .at_least(0),
        ParameterDecl::integer("patience", "steps", "see tolerance").fallback(15).within({.min = 1, .max = 1000000}),
        ParameterDecl::integer("sharp_every", "states", "the sharp problem on every k-th accepted state (J_sharp is "
                                                        "empty on the others)")
            .fallback(1)
            .within({.min = 1, .max = 1000000}),
        ParameterDecl::choice("volume_mesh", {"fixed", "remeshed"},
                              "fixed: the smoothed problem on one volume mesh of S⁰ for the whole run, d_G carried to "
                              "it; remeshed: a new volume mesh of every state")
            .fallback("remeshed"),
        ParameterDecl::boolean("sharp", "solve the sharp problem (4.12) on every accepted state's volume mesh "
                                        "and report J_sharp (one more solve)")
            .fallback(true),
        ParameterDecl::integer("nucleation.every", "steps", "a new component of G (a disk) where J's topological "
                                                            "sensitivity 4γup is most negative, on the steps from "
                                                            "every k-th state (0: never)")
            .fallback(0)
            .within({.min = 0, .max = 1000000}),
        ParameterDecl::number("nucleation.radius", "length", "ρ of each new disk")
            .computed("2 × the mean edge h of T^0")
            .positive(),
        ParameterDecl::number("nucleation.clearance", "length", "kept between a new disk and G, Γ_N and the other new "
                                                               "disks")
            .computed("epsilon + the mean edge h of T^0")
            .at_least(0),
        ParameterDecl::integer("nucleation.count", "disks", "new disks at most per nucleation").fallback(1).within(
            {.min = 1, .max = 1000}),
        ParameterDecl::integer("volume_every", "states", "write volume_NNNNN.vtu (tetrahedra with u) every k states (0: "
                                                         "never)")
            .fallback(0)
            .within({.min = 0, .max = 1000000}),
    };
  }

  std::vector<OutputDecl> outputs() const override {
    return {OutputDecl::metric("slope", "temperature/time", "J′(v): the derivative of the merit along the descent speed"),
            OutputDecl::metric("stationarity", "1", "|J′(v)| / |J′(v⁰)|: the stop's measure"),
            OutputDecl::metric("area_rate", "area/time", "∫_Σ v: the rate of change of |G| along the descent speed"),
            OutputDecl::metric("ms_regularise", "ms", "the H¹ regularisation's solve"),
            OutputDecl::metric("J", "temperature", "the merit j + ℓ|G| (+ the area constraint's terms) of the accepted "
                                                   "state"),
            OutputDecl::metric("j", "temperature", "the objective functional j(u)"),
            OutputDecl::metric("forced", "1", "1 when the step was taken although it raised J"),
            OutputDecl::metric("T", "temperature", "mean temperature over the part"),
            OutputDecl::metric("area_G", "area", "|G|"),
            OutputDecl::metric("lambda", "temperature/area", "the multiplier λ of the area constraint (0 without)"),
            OutputDecl::metric("length_Sigma", "length", "|∂G|"),
            OutputDecl::metric("decrease", "1", "relative decrease of J over the step"),
            OutputDecl::metric("step", "time", "the step taken"),
            OutputDecl::metric("noise", "1", "the relative noise of J the sufficient-decrease test tolerates"),
            OutputDecl::metric("scatter", "1", "the relative scatter of j between two meshes of G⁰ (measured at T⁰)"),
            OutputDecl::metric("epsilon", "length", "ε of the next step (the continuation shrinks it)"),
            OutputDecl::metric("tets", "1", "tetrahedra of the volume mesh"),
            OutputDecl::metric("ms_tetgen", "ms", "tetrahedralisation"),
            OutputDecl::metric("ms_assembly", "ms", "set-up and assembly"),
            OutputDecl::metric("ms_factor", "ms", "analysis and factorisation"),
            OutputDecl::metric("ms_solve", "ms", "solves"),
            OutputDecl::metric("T_sharp", "temperature", "the mean temperature of the sharp problem (4.12): u = 0 on "
                                                         "G's faces (sharp = true)"),
            OutputDecl::metric("J_sharp", "temperature", "j(u_sharp) + ell·|G|: the objective J_ε approximates"),
            OutputDecl::metric("ms_sharp", "ms", "the sharp problem's assembly and solve"),
            OutputDecl::metric("nucleated", "disks", "new components of G the accepted step created (nucleation)"),
            OutputDecl::metric("nucleation_predicted", "temperature", "their predicted change of J: Σ ρ·4γup at the "
                                                                      "centres, and the merit's change with their "
                                                                      "area"),
            OutputDecl::vertex_field("temperature", "temperature", "u at the surface's vertices"),
            OutputDecl::vertex_field("adjoint", "", "p at the surface's vertices"),
            OutputDecl::vertex_field("shape_gradient", "", "the density w of J′ on the surface"),
            OutputDecl::vertex_field("descent_speed", "1", "v, the normal speed of the descent (max |v| = 1)"),
            OutputDecl::vertex_field("topological_sensitivity", "temperature/length",
                                     "4γup: J's change per unit radius of a new disk of G centred there"),
            OutputDecl::file("objective.csv", "j, |G|, J and the slope of every accepted state from T^0, per continuation "
                                              "stage"),
            OutputDecl::file("volume.pvd", "the series of volume_NNNNN.vtu (with volume_every)")};
  }

  void configure(Parameters& p) override {
    ell_ = p.number("ell");
    read_objective(p);
    read_area(p);
    epsilon_ = p.number("epsilon", 0);
    epsilon_final_ = p.number("epsilon_final", 0);
    continuation_factor_ = p.number("continuation_factor");
    if (epsilon_ > 0 && epsilon_final_ > epsilon_)
      p.fail("epsilon_final", fmt::format("{} is above epsilon = {}: the continuation only shrinks ε", epsilon_final_, epsilon_));
    alpha_ = p.number("alpha");
    conductivity_ = read_box_field(p, "conductivity");
    source_ = read_box_field(p, "source");
    if (p.has("neumann")) {
      Parameters& n = p.section("neumann");
      neumann_.value = n.number("flux");
      for (const auto& box : n.points("boxes")) {
        std::array<double, 7> b{};
        std::copy(box.begin(), box.end(), b.begin());
        neumann_.boxes.push_back(b);
      }
    }
    tetgen_.radius_edge_ratio = p.number("radius_edge");
    volume_factor_ = p.number("volume_factor");
    solver_.solver = linear_solver_from_string(p.choice("solver"));
    DescentOptions& d = descent_.options();
    d.ell = ell_;
    d.armijo = p.number("armijo");
    noise_given_ = p.number("noise", -1);
    min_step_factor_ = p.number("min_step_factor");
    d.grow = p.number("grow");
    max_dt_factor_ = p.number("max_dt_factor");
    d.stationarity = p.number("stationarity");
    d.tolerance = p.number("tolerance");
    d.patience = int(p.integer("patience"));
    volume_every_ = int(p.integer("volume_every"));
    if (p.has("nucleation")) {
      Parameters& n = p.section("nucleation");
      nucleation_every_ = int(n.integer("every"));
      if (nucleation_every_ == 0) {
        for (const char* key : {"radius", "clearance", "count"}) n.not_used(key, "nucleation.every = 0");
      } else {
        nucleation_.radius = n.number("radius", 0);
        nucleation_.clearance = n.number("clearance", -1);
        nucleation_.count = int(n.integer("count"));
      }
    }
    sharp_ = p.boolean("sharp");
    fixed_volume_ = p.choice("volume_mesh") == "fixed";
    sharp_every_ = int(p.integer("sharp_every"));
    if (!sharp_) p.not_used("sharp_every", "sharp = false");
  }

  // d everywhere: the shape gradient is extended over the whole skin, and nucleation looks for sites anywhere.
  ModelNeeds needs() const override {
    // The state and adjoint are solved on the whole part: every triangle of its skin enters J.
    return {.may_reject = true, .freeze_velocity = true, .whole_surface_distance = true, .remesh_everywhere = true};
  }

  VelocityField compute(const StepContext& context) override {
    resolve_lengths(context);
    if (!current_ || current_->iteration != context.iteration())
      current_ = evaluate(context.mesh(), context.distance(), context.mesh_size(), context.iteration());
    Evaluation& e = *current_;
    if (descent_.records().empty()) {
      start(context, e);
      direct(context, e);
      descent_.set_slope(e.unit_slope);
    } else if (e.speed.empty()) {  // a resumed run's first state
      direct(context, e);
    }
    slope_ = e.slope;

    VelocityField field = VelocityField::normal(e.speed);
    const double first = descent_.records().front().slope;
    field.metrics = {{"slope", slope_},
                     {"stationarity", first != 0 ? std::abs(e.unit_slope / first) : 1.0},
                     {"area_rate", e.area_rate},
                     {"ms_regularise", e.ms_direction}};
    if (e.sensitivity.empty()) e.sensitivity = topological_sensitivity(context.mesh(), e.u_surface, e.p_surface, conductivity_);
    field.point_fields = {{"temperature", e.u_surface},
                          {"adjoint", e.p_surface},
                          {"shape_gradient", e.objective.density},
                          {"descent_speed", e.speed},
                          {"topological_sensitivity", e.sensitivity}};
    return field;
  }

  /// Nucleation: on the steps from every k-th state, disks where 4γup is most negative; none on a
  /// retry (the review refused the step with them).
  std::vector<Nucleus> nuclei(const StepContext& state, int attempt) override {
    nucleated_ = {};
    const int n = state.iteration();
    if (nucleation_every_ == 0 || attempt > 0 || n == 0 || n % nucleation_every_ != 0) return {};
    if (!current_ || current_->iteration != n) return {};
    Evaluation& e = *current_;
    if (e.sensitivity.empty()) e.sensitivity = topological_sensitivity(state.mesh(), e.u_surface, e.p_surface, conductivity_);
    const std::vector<int> sites =
        nucleation_sites(state.mesh(), state.distance(), e.sensitivity, neumann_vertices(state.mesh()), nucleation_);
    // The merit's change: the disks' first-order ρ·g, and what their area costs (ℓ, the constraint).
    double predicted = 0;
    for (int v : sites) predicted += nucleation_.radius * e.sensitivity[std::size_t(v)];
    const double added = double(sites.size()) * std::numbers::pi * nucleation_.radius * nucleation_.radius;
    predicted += descent_.merit(e.objective.j, e.objective.area + added) - descent_.merit(e.objective.j, e.objective.area);
    if (sites.empty() || !(predicted < 0)) return {};
    std::vector<Nucleus> out;
    for (int v : sites) out.push_back({v, nucleation_.radius});
    nucleated_ = {int(out.size()), predicted};
    spdlog::info("thermal, step {}: {} new component(s) of G of radius {:.4g}, predicted dJ = {:.4g}", n + 1, out.size(),
                 nucleation_.radius, predicted);
    return out;
  }

  Review review(const StepContext& candidate, int attempt) override {
    std::shared_ptr<Evaluation> next;
    try {
      next = evaluate(candidate.mesh(), candidate.distance(), candidate.mesh_size(), candidate.iteration());
    } catch (const InputError& error) {
      // A candidate TetGen cannot mesh (a remeshing defect such as a degenerate triangle) is a bad
      // step, not the end of the run: the driver retries with a shorter one.
      std::string kept;
      if (!candidate.output_dir().empty()) {  // the mesh TetGen refused, for a bug report
        const auto file = candidate.output_dir() / fmt::format("untetrahedralisable_{:05d}.mesh", candidate.iteration());
        write_mesh(candidate.mesh(), file);
        kept = fmt::format(" (kept as {})", file.string());
      }
      return Review::reject(fmt::format("the candidate cannot be tetrahedralised{}: {}", kept, error.what()));
    }
    const ThermalObjective now = current_->objective;
    const double J = descent_.merit(now.j, now.area);
    const double noise_before = descent_.options().noise;
    const Descent::Verdict verdict =
        descent_.judge(now.j, now.area, slope_, candidate.dt(), max_speed(current_->speed), next->objective.j,
                       next->objective.area, attempt);
    const double J_next = descent_.merit(next->objective.j, next->objective.area);
    const std::string why = fmt::format("J = {:.8g} > {:.8g} (J^n = {:.8g}, Armijo with noise {:.3g}, dt = {:.4g}; |G| "
                                        "{:.5g} -> {:.5g})",
                                        J_next, verdict.bound, J, noise_before, candidate.dt(), now.area,
                                        next->objective.area);
    if (descent_.options().noise > noise_before)
      spdlog::info("thermal, step {}: a short step raised J by {:.3g} (relative), more than it predicts: noise {:.3g} -> "
                   "{:.3g}",
                   candidate.iteration(), (J_next - J) / std::abs(J), noise_before, descent_.options().noise);
    if (!verdict.accept) return Review::reject(why);
    // A new component is judged on its own merit: the shortest-step rule is for the motion's noise.
    if (verdict.forced && attempt == 0 && nucleated_.count > 0) return Review::reject(why + "; with the new component(s)");
    if (verdict.forced) spdlog::warn("thermal, step {}: the shortest step still raises J ({}); taken", candidate.iteration(), why);
    const double decrease = (J - J_next) / std::abs(J);
    const double lambda = descent_.lambda();
    const double speed = max_speed(current_->speed);
    descent_.accept(next->objective.j, next->objective.area);
    direct(candidate, *next);  // the next step's direction, and the stationarity of this state
    descent_.set_slope(next->unit_slope);
    write_volume(*next, candidate);
    const auto [T_sharp, j_sharp, ms_sharp] = sharp_objective(candidate.mesh(), *next);
    const ThermalObjective o = next->objective;  // at the step's ε (before a continuation)
    const ThermalTimings t = next->solution.timings;
    std::string stop = descent_.stop_reason();
    bool continued = false;
    if (!stop.empty() && epsilon_ > 1.25 * epsilon_final_) {  // a stage for less than 20 % of ε is not worth it
      // ε continuation: the design has settled for this ε; go on with a narrower band, closer to
      // the sharp problem. The candidate is evaluated again with the new ε.
      const double previous = epsilon_;
      epsilon_ = std::max(continuation_factor_ * epsilon_, epsilon_final_);
      if (fixed_) fixed_->set_robin_coefficient([e = epsilon_](double d) { return h_epsilon(d, e); });
      descent_.options().max_motion = std::min(descent_.options().max_motion, epsilon_ / 2);
      next = evaluate(candidate.mesh(), candidate.distance(), candidate.mesh_size(), candidate.iteration());
      descent_.new_stage(next->objective.j, next->objective.area);
      direct(candidate, *next);
      descent_.set_slope(next->unit_slope);
      spdlog::info("thermal, step {}: {}; epsilon {:.4g} -> {:.4g}: J = {:.8g} (j = {:.8g})", candidate.iteration(), stop,
                   previous, epsilon_, descent_.merit(next->objective.j, next->objective.area), next->objective.j);
      stop.clear();
      continued = true;
    }
    Review r = stop.empty() ? Review::accept() : Review::accept_and_stop(stop);
    r.next_dt = descent_.next_step(candidate.dt(), speed, attempt, J_next > J, max_speed(next->speed));
    if (continued) r.next_dt = descent_.stage_step(max_speed(next->speed));
    r.metrics = {{"J", J_next},
                 {"j", o.j},
                 {"forced", verdict.forced ? 1.0 : 0.0},
                 {"T", o.T},
                 {"area_G", o.area},
                 {"lambda", lambda},
                 {"length_Sigma", next->interface_length},
                 {"decrease", decrease},
                 {"step", candidate.dt()},
                 {"noise", descent_.options().noise},
                 {"scatter", scatter_},
                 {"epsilon", epsilon_},
                 {"tets", double(next->solved_on->n_tets())},
                 {"ms_tetgen", next->ms_tetrahedralize},
                 {"ms_assembly", t.setup_ms + t.assembly_ms},
                 {"ms_factor", t.analysis_ms + t.factorization_ms},
                 {"ms_solve", t.solve_ms},
                 {"T_sharp", T_sharp},
                 {"J_sharp", j_sharp + ell_ * o.area},
                 {"ms_sharp", ms_sharp},
                 {"nucleated", attempt == 0 ? double(nucleated_.count) : 0.0},
                 {"nucleation_predicted", attempt == 0 ? nucleated_.predicted : 0.0}};
    current_ = std::move(next);  // T^{n+1} is the next compute's state
    return r;
  }

  /// objective.csv: every accepted state from T^0 (history.csv starts at row 1, the first state a
  /// review measured).
  void finish(const StepContext& final_state, ModelOutputs& /*outputs*/) override {
    const std::filesystem::path& output_dir = final_state.output_dir();
    if (output_dir.empty() || descent_.records().empty()) return;
    write_atomically(output_dir / "objective.csv", [&](std::ostream& out) {
      out << "record,stage,j,area_G,J,slope\n";
      const auto& records = descent_.records();
      for (std::size_t i = 0; i < records.size(); ++i)
        out << fmt::format("{},{},{:.17g},{:.17g},{:.17g},{:.17g}\n", i, records[i].stage, records[i].j, records[i].area,
                           descent_.merit(records[i].j, records[i].area), records[i].slope);
    });
  }

  void save_state(ModelState& state) const override {
    state.version = 2;
    std::vector<double> j, area, slope, stage;
    for (const auto& r : descent_.records())
      j.push_back(r.j), area.push_back(r.area), slope.push_back(r.slope), stage.push_back(r.stage);
    state.set("stage", stage);
    state.set("j", j);
    state.set("area", area);
    state.set("slope", slope);
    const DescentOptions& d = descent_.options();
    state.set("lengths", std::vector<double>{epsilon_, alpha_length_, d.min_step, d.max_step, d.max_motion, speed_scale_,
                                             epsilon_final_});
    state.set("descent", std::vector<double>{d.noise, d.penalty, descent_.lambda(), descent_.motion(), scatter_});
    if (d.target) state.set("area_target", std::vector<double>{*d.target});  // fixed on T⁰ (area.fraction of |S⁰|)
    if (nucleation_every_ > 0) state.set("nucleation", std::vector<double>{nucleation_.radius, nucleation_.clearance});
    if (fixed_) {  // S⁰, so that a resumed run solves on the same volume mesh
      std::vector<double> points;
      for (const Vec3& x : fixed_->points()) points.insert(points.end(), {x[0], x[1], x[2]});
      std::vector<std::int64_t> faces;
      for (auto f : fixed_->surface().faces())
        for (auto v : fixed_->surface().fv_range(f)) faces.push_back(v.idx());
      state.set("s0_points", points);
      state.set("s0_faces", faces);
      // The conjugate gradient's warm start: a resumed run's solves then start where the run's did.
      const Eigen::MatrixXd& warm = fixed_->solver().warm_start();
      state.set("warm_start", std::vector<double>(warm.data(), warm.data() + warm.size()));
    }
  }

  void load_state(const ModelState& state) override {
    if (state.version != 2)
      throw InputError(fmt::format("thermal model state version {} (this plugin reads version 2: resume with the "
                                   "plugin that wrote it, or start again)",
                                   state.version));
    const auto &j = state.numbers("j"), &area = state.numbers("area"), &slope = state.numbers("slope"),
               &stage = state.numbers("stage");
    if (area.size() != j.size() || slope.size() != j.size() || stage.size() != j.size())
      throw InputError("thermal model state: 'j', 'area', 'slope' and 'stage' differ in length");
    std::vector<DescentRecord> records;
    for (std::size_t i = 0; i < j.size(); ++i) records.push_back({j[i], area[i], slope[i], int(stage[i])});
    descent_.set_records(std::move(records));
    const auto& lengths = state.numbers("lengths");
    const auto& descent = state.numbers("descent");
    if (lengths.size() != 7 || descent.size() != 5)
      throw InputError("thermal model state: 'lengths' needs 7 numbers and 'descent' 5");
    DescentOptions& d = descent_.options();
    epsilon_ = lengths[0], alpha_length_ = lengths[1], d.min_step = lengths[2], d.max_step = lengths[3];
    d.max_motion = lengths[4], speed_scale_ = lengths[5], epsilon_final_ = lengths[6];
    if (state.has("s0_points")) {
      const auto& points = state.numbers("s0_points");
      const auto& faces = state.integers("s0_faces");
      if (points.size() % 3 != 0 || faces.size() % 3 != 0)
        throw InputError("thermal model state: 's0_points' and 's0_faces' need triples");
      SurfaceMesh s0;
      for (std::size_t i = 0; i < points.size(); i += 3) s0.add_vertex(Vec3(points[i], points[i + 1], points[i + 2]));
      for (std::size_t i = 0; i < faces.size(); i += 3) {
        for (std::size_t k = 0; k < 3; ++k)
          if (faces[i + k] < 0 || std::size_t(faces[i + k]) >= s0.n_vertices())
            throw InputError("thermal model state: 's0_faces' names a vertex S⁰ does not have");
        s0.add_face(s0.vertex_handle(int(faces[i])), s0.vertex_handle(int(faces[i + 1])),
                    s0.vertex_handle(int(faces[i + 2])));
      }
      resumed_surface_ = std::move(s0);
      resumed_warm_start_ = state.numbers("warm_start");
    }
    if (nucleation_every_ > 0) {  // the radius and clearance resolved on T⁰
      const auto& nucleation = state.numbers("nucleation");
      if (nucleation.size() != 2) throw InputError("thermal model state: 'nucleation' needs 2 numbers");
      nucleation_.radius = nucleation[0], nucleation_.clearance = nucleation[1];
    }
    if (area_target_ > 0 || area_fraction_ > 0) {
      if (!state.has("area_target") || state.numbers("area_target").size() != 1)
        throw InputError("thermal model state: the case has a target area and the checkpoint none (written without "
                         "[model.area]?)");
      d.target = state.numbers("area_target")[0];
    }
    d.noise = descent[0], d.penalty = descent[1];
    descent_.set_lambda(descent[2]);
    descent_.set_motion(descent[3]);
    scatter_ = descent[4];
    lengths_resolved_ = true;
  }

 private:
  static double max_speed(const ScalarField& v) {
    double m = 0;
    for (double x : v) m = std::max(m, std::abs(x));
    return m;
  }

  /// The descent speed on e's state: (M + α²K) v = −(b_w + ℓ_eff b_Σ), b_w the band's derivative
  /// carried onto Σ and b_Σ the interface's length load (shape_derivative.hpp), scaled as said below, then
  /// extended constant along Σ's normals and zero on Γ_N; and the slope M′(v) = b_wᵀv + ℓ_eff b_Σᵀv
  /// (< 0).
  void direct(const StepContext& context, Evaluation& e) {
    const auto started = std::chrono::steady_clock::now();
    const SurfaceMesh& mesh = context.mesh();
    // The derivative's load: the band's carried onto Σ (projected_band_load: what a step of the
    // pipeline sees), and ℓ_eff times the interface's length load.
    const double reach = epsilon_ + 2 * context.mesh_size();
    const InterfaceProjection onto = project_onto_interface(mesh, e.sample_points, reach);
    const Eigen::VectorXd band = projected_band_load(onto, e.band_weights, mesh.n_vertices());
    const InterfaceProjection projection = fixed_volume_ ? project_onto_interface(mesh, reach) : onto;
    const Eigen::VectorXd length = interface_length_load(mesh);
    Eigen::VectorXd rhs = band + descent_.area_weight(e.objective.area) * length;
    Eigen::SparseMatrix<double> system = context.mass_matrix() + (alpha_length_ * alpha_length_) * context.stiffness_matrix();
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system);
    if (ldlt.info() != Eigen::Success) throw InputError("thermal: the H¹ regularisation system is singular");
    Eigen::VectorXd v = -ldlt.solve(rhs);
    const std::vector<char> fixed = neumann_vertices(mesh);
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (fixed[std::size_t(i)]) v[i] = 0;
    // Scaled by the first state's largest speed (or its own, when larger): max |v| ≤ 1, so that Δt
    // bounds the front's motion, and v fades with the gradient, so that steps shrink near a
    // stationary point instead of oscillating about it at full length.
    const double largest = v.cwiseAbs().maxCoeff();
    if (speed_scale_ == 0) speed_scale_ = largest;
    const double scale = std::max(largest, speed_scale_);
    if (scale > 0) v /= scale;
    e.slope = rhs.dot(v);
    e.area_rate = length.dot(v);
    e.unit_slope = scale > 0 ? e.slope * scale / largest : 0;
    e.speed = extend_from_interface(projection, std::vector<double>(v.data(), v.data() + v.size()));
    for (std::size_t i = 0; i < e.speed.size(); ++i)
      if (fixed[i]) e.speed[i] = 0;
    e.ms_direction = ms_since(started);
  }

  void read_objective(Parameters& p) {
    if (!p.is_table("objective")) {
      objective_.kind = objective_kind_from_string(p.choice("objective"));
    } else {
      Parameters& o = p.section("objective");
      objective_.kind = objective_kind_from_string(o.choice("kind"));
      if (objective_.kind == ObjectiveKind::max_temperature) objective_.exponent = o.number("exponent");
      if (objective_.kind == ObjectiveKind::region_mean) {
        for (const auto& box : o.points("boxes")) {
          std::array<double, 6> b{};
          std::copy(box.begin(), box.end(), b.begin());
          for (int k = 0; k < 3; ++k)
            if (!(b[std::size_t(k)] <= b[std::size_t(k) + 3]))
              o.fail("boxes", fmt::format("a box's min corner must not exceed its max corner (axis {})", "xyz"[k]));
          objective_.boxes.push_back(b);
        }
        if (objective_.boxes.empty()) o.fail("boxes", "region_mean needs at least one box");
      }
      o.not_used("exponent", "only max_temperature has an exponent");
      o.not_used("boxes", "only region_mean has boxes");
    }
    if (objective_.kind == ObjectiveKind::region_mean && objective_.boxes.empty())
      p.fail("objective", "region_mean needs its boxes: [model.objective] kind = \"region_mean\", boxes = [[...]]");
  }

  void read_area(Parameters& p) {
    if (!p.has("area")) return;
    Parameters& a = p.section("area");
    if (a.has("target") == a.has("fraction")) a.fail("give one of target (an area) and fraction (of |S|)");
    if (a.has("target")) area_target_ = a.number("target");
    else area_fraction_ = a.number("fraction");
    area_penalty_factor_ = a.number("penalty");
    descent_.options().update_every = int(a.integer("update_every"));
    descent_.options().area_tolerance = a.number("tolerance");
  }

  /// ε and α·h from the first mesh (kept in the state, so a resumed run uses the same).
  void resolve_lengths(const StepContext& context) {
    if (lengths_resolved_) return;
    const double h = context.mesh_size();
    if (!(epsilon_ > 0)) epsilon_ = 3 * h;
    if (!(epsilon_final_ > 0)) epsilon_final_ = std::min(epsilon_, h);
    if (epsilon_final_ > epsilon_)
      throw InputError(fmt::format("[model] epsilon_final = {:.4g} is above epsilon = {:.4g}: the continuation only "
                                   "shrinks ε",
                                   epsilon_final_, epsilon_));
    if (epsilon_final_ < h) {
      const std::string what = fmt::format("{} = {:.4g} is below the mesh size h = {:.4g}: the band of h_ε is not "
                                           "resolved by the surface mesh",
                                           epsilon_final_ < epsilon_ ? "epsilon_final" : "epsilon", epsilon_final_, h);
      if (!sharp_) throw InputError(fmt::format("[model] {} (set sharp = true to follow the true objective, or a larger "
                                                "epsilon)",
                                                what));
      spdlog::warn("thermal: [model] {}; J_sharp is the objective to read", what);
    }
    alpha_length_ = alpha_ * h;
    // Δt: the front moves at most max|v|·Δt per step; ≤ h keeps it within an element and ≤ ε/2 within
    // half the Robin band. The case's Δt sets the shortest step and the cap.
    DescentOptions& d = descent_.options();
    d.min_step = min_step_factor_ * context.dt();
    d.max_step = max_dt_factor_ * context.dt();
    d.max_motion = std::min(h, epsilon_ / 2);
    if (!(nucleation_.radius > 0)) nucleation_.radius = 2 * h;
    if (nucleation_.clearance < 0) nucleation_.clearance = epsilon_ + h;
    lengths_resolved_ = true;
  }

  /// The first state: the area target, μ and the noise of j (measured unless given).
  void start(const StepContext& context, const Evaluation& e) {
    DescentOptions& d = descent_.options();
    const SurfaceMesh& mesh = context.mesh();
    double surface_area = 0;
    for (auto f : mesh.faces()) surface_area += mesh.calc_face_area(f);
    if (area_fraction_ > 0) area_target_ = area_fraction_ * surface_area;
    if (area_target_ > 0) {
      if (!(area_target_ < surface_area))
        throw InputError(fmt::format("[model.area] target = {:.6g} is not below |S| = {:.6g}", area_target_, surface_area));
      d.target = area_target_;
      d.penalty = area_penalty_factor_ * std::abs(e.objective.j) / (area_target_ * area_target_);
    }
    scatter_ = measure_scatter(context, e);
    d.noise = noise_given_ >= 0 ? noise_given_ : std::min(d.max_noise, 2 * scatter_);
    descent_.accept(e.objective.j, e.objective.area);
    spdlog::info("thermal: J = {:.8g} (j = {:.8g} [{}], |G| = {:.6g}{}) on T^{}, {} tetrahedra, eps = {:.4g}, alpha = "
                 "{:.4g}, noise {:.3g}{}, dt in [{:.3g}, {:.3g}]",
                 descent_.merit(e.objective.j, e.objective.area), e.objective.j, to_string(objective_.kind),
                 e.objective.area, d.target ? fmt::format(", target {:.6g}", *d.target) : "", context.iteration(),
                 e.solved_on->n_tets(), epsilon_, alpha_length_, d.noise, noise_given_ >= 0 ? " (given)" : " (measured)",
                 d.min_step, d.max_step);
  }

  /// The relative difference of j between T⁰ and a second mesh of the same G (remeshed everywhere
  /// at the same sizes, its distance recomputed): the scatter a step's remesh and tetrahedralisation
  /// add to j, which the sufficient-decrease test must tolerate (twice it is the default noise).
  double measure_scatter(const StepContext& context, const Evaluation& e) {
    SurfaceMesh other = context.mesh();
    RemeshOptions options;
    options.hmax = resolution_length(other);  // the sizes a run's remesh keeps
    options.hausd = 0.1 * context.mesh_size();
    options.incremental = false;
    remesh(other, options);
    const ScalarField distance = signed_distance_to_region(other);
    std::shared_ptr<Evaluation> second;
    try {
      second = evaluate(other, distance, context.mesh_size(), context.iteration());
    } catch (const InputError& error) {  // a second mesh TetGen or the surface check refuses
      spdlog::warn("thermal: no second mesh of G^0 to measure the noise of J on ({}); the steps' retries will", error.what());
      return 0;
    }
    const double scatter = std::abs(second->objective.j - e.objective.j) / std::abs(e.objective.j);
    spdlog::info("thermal: j = {:.8g} on T^0 and {:.8g} on a second mesh of G^0 ({} and {} faces): relative scatter "
                 "{:.3g}",
                 e.objective.j, second->objective.j, context.mesh().n_faces(), other.n_faces(), scatter);
    return scatter;
  }

  std::shared_ptr<Evaluation> evaluate(const SurfaceMesh& mesh, const ScalarField& distance, double mesh_size,
                                       int iteration) {
    auto e = std::make_shared<Evaluation>();
    e->iteration = iteration;
    const double epsilon = epsilon_;
    ThermalOptions options;
    options.linear = solver_;
    ObjectiveOptions objective{.epsilon = epsilon_, .ell = ell_, .quadrature = options.quadrature};
    auto failed = [&](const InputError& error) {
      return InputError(fmt::format("thermal, iteration {}: {}", iteration, error.what()));
    };
    if (fixed_volume_) {
      options.adjoint_shortcut = true;  // p = −u/|Ω| where it holds (thermal_fem.hpp): one solve, not two
      try {
        if (!fixed_) build_fixed(resumed_surface_ ? *resumed_surface_ : mesh, mesh_size, options);
        // The state must still be the skin of a solid (TetGen checked it in "remeshed" mode): a
        // folded candidate is rejected and the step retried.
        check_solid_surface(mesh);
        // d_G carried to S⁰, the smoothed problem there, and u, p, w brought back to T^n.
        const std::vector<double> d0 = fixed_->carry(mesh, distance);
        e->solution = fixed_->solve(d0);
        objective.neumann = fixed_neumann_;
        e->objective = thermal_objective(fixed_->surface(), d0, e->solution, objective);
        e->band_weights = band_weights(fixed_->surface(), d0, e->solution, objective);
      } catch (const InputError& error) {
        throw failed(error);
      }
      e->solved_on = &fixed_->volume();
      e->sample_points = fixed_->points();
      const SurfaceLocations at = fixed_->locate_vertices_of(mesh);
      const auto n0 = std::size_t(fixed_->volume().n_surface_vertices);
      e->u_surface = interpolate(at, std::vector<double>(e->solution.u.data(), e->solution.u.data() + n0));
      e->p_surface = interpolate(at, std::vector<double>(e->solution.p.data(), e->solution.p.data() + n0));
      e->objective.density = interpolate(at, e->objective.density);
      // |G| from the state's own labels (S⁰'s are G⁰'s).
      e->objective.area = 0;
      for (auto f : mesh.faces())
        if (mesh.inside(f)) e->objective.area += mesh.calc_face_area(f);
      e->objective.J = e->objective.j + ell_ * e->objective.area;
    } else {
      auto started = std::chrono::steady_clock::now();
      TetrahedralizeOptions tetgen = tetgen_;
      if (volume_factor_ > 0) tetgen.max_volume = volume_factor_ * regular_tet_volume(mesh_size);
      ThermalProblem problem = base_problem(mesh);
      problem.robin_field = distance;
      problem.robin_coefficient = [epsilon](double d) { return h_epsilon(d, epsilon); };
      objective.neumann = problem.neumann;
      try {
        e->volume = tetrahedralize(mesh, tetgen);
        e->ms_tetrahedralize = ms_since(started);
        e->solution = solve_thermal(e->volume, problem, options);
      } catch (const InputError& error) {
        throw failed(error);
      }
      e->objective = thermal_objective(mesh, distance, e->solution, objective);
      e->band_weights = band_weights(mesh, distance, e->solution, objective);
      e->solved_on = &e->volume;
      e->sample_points = vertex_points(mesh);
      const auto n = std::size_t(mesh.n_vertices());
      e->u_surface.assign(e->solution.u.data(), e->solution.u.data() + n);
      e->p_surface.assign(e->solution.p.data(), e->solution.p.data() + n);
    }
    for (auto edge : mesh.edges())
      if (mesh.interface(edge)) e->interface_length += mesh.calc_edge_length(edge);
    return e;
  }

  /// The volume mesh of the smoothed problem for the whole run, from S⁰ (T⁰, or the surface a
  /// checkpoint kept).
  void build_fixed(const SurfaceMesh& surface, double mesh_size, const ThermalOptions& options) {
    SurfaceMesh s0 = surface;
    s0.garbage_collection();
    TetrahedralizeOptions tetgen = tetgen_;
    if (volume_factor_ > 0) tetgen.max_volume = volume_factor_ * regular_tet_volume(mesh_size);
    ThermalProblem problem = base_problem(s0);
    const double epsilon = epsilon_;
    problem.robin_coefficient = [epsilon](double d) { return h_epsilon(d, epsilon); };
    fixed_neumann_ = problem.neumann;
    fixed_ = std::make_unique<FixedVolume>(std::move(s0), tetgen, std::move(problem), options);
    if (!resumed_warm_start_.empty()) {
      const auto n = Eigen::Index(fixed_->volume().n_vertices());
      if (Eigen::Index(resumed_warm_start_.size()) != 2 * n)
        throw InputError(fmt::format("thermal model state: 'warm_start' has {} values for 2 × {} volume vertices",
                                     resumed_warm_start_.size(), n));
      fixed_->solver().set_warm_start(Eigen::Map<const Eigen::MatrixXd>(resumed_warm_start_.data(), n, 2));
      resumed_warm_start_.clear();
    }
    spdlog::info("thermal: the smoothed problem's volume mesh: {} tetrahedra from {} surface faces, once ({:.0f} ms)",
                 fixed_->volume().n_tets(), fixed_->surface().n_faces(), fixed_->ms_tetrahedralize());
  }

  /// The true objective beside the smoothed one: u = 0 on G's faces of the same volume mesh.
  /// {T_sharp, j_sharp, ms}; NaN when off or when it has no solution.
  std::array<double, 3> sharp_objective(const SurfaceMesh& mesh, const Evaluation& e) const {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (!sharp_ || e.iteration % sharp_every_ != 0) return {nan, nan, 0};
    FaceMask g(mesh.n_faces(), 0);
    for (auto f : mesh.faces()) g[std::size_t(f.idx())] = mesh.inside(f);
    try {
      // Σ must be in the mesh: the state's own volume mesh (a new one with volume_mesh = "fixed").
      const auto started = std::chrono::steady_clock::now();
      VolumeMesh own;
      if (fixed_volume_) own = tetrahedralize(mesh, tetgen_);
      const SharpSolution sharp = solve_sharp(fixed_volume_ ? own : e.volume, base_problem(mesh), g, solver_);
      return {sharp.mean_temperature, sharp.objective, ms_since(started)};
    } catch (const InputError& error) {
      spdlog::warn("thermal, step {}: no sharp J ({})", e.iteration, error.what());
      return {nan, nan, 0};
    }
  }

  /// The part's conductivity, source, Neumann boxes and objective on `mesh` (the smoothed problem
  /// adds its Robin term, the sharp one holds G at 0).
  ThermalProblem base_problem(const SurfaceMesh& mesh) const {
    ThermalProblem problem;
    if (!conductivity_.constant() || conductivity_.value != 1) problem.conductivity = conductivity_;
    if (!source_.constant() || source_.value != 1) problem.source = source_;
    const FaceMask neumann = neumann_faces(mesh);
    if (!neumann.empty()) {
      problem.neumann = neumann;
      problem.neumann_flux = neumann_;  // g: a box's value on its faces
    }
    problem.objective = objective_;
    return problem;
  }

  FaceMask neumann_faces(const SurfaceMesh& mesh) const {
    if (neumann_.boxes.empty()) return {};
    FaceMask mask(mesh.n_faces(), 0);
    std::size_t count = 0;
    for (auto f : mesh.faces()) count += mask[std::size_t(f.idx())] = neumann_.inside_any(mesh.calc_face_centroid(f));
    return count ? mask : FaceMask{};
  }

  /// Vertices of Γ_N faces: the descent speed is zero there, so G does not enter Γ_N.
  std::vector<char> neumann_vertices(const SurfaceMesh& mesh) const {
    std::vector<char> fixed(mesh.n_vertices(), 0);
    const FaceMask faces = neumann_faces(mesh);
    if (faces.empty()) return fixed;
    for (auto f : mesh.faces())
      if (faces[std::size_t(f.idx())])
        for (auto v : mesh.fv_range(f)) fixed[std::size_t(v.idx())] = 1;
    return fixed;
  }

  void write_volume(const Evaluation& e, const StepContext& candidate) {
    if (volume_every_ == 0 || candidate.output_dir().empty() || candidate.iteration() % volume_every_ != 0) return;
    const std::string name = fmt::format("volume_{:05d}.vtu", candidate.iteration());
    write_volume_vtu(*e.solved_on, {{"temperature", &e.solution.u}, {"adjoint", &e.solution.p}},
                     candidate.output_dir() / name);
    if (!volume_pvd_)
      volume_pvd_ = std::make_unique<PvdWriter>(
          PvdWriter::resume(candidate.output_dir() / "volume.pvd", candidate.time() - 0.5 * candidate.dt()));
    volume_pvd_->add(candidate.time(), name);
  }

  // Parameters.
  double ell_ = 0.01, epsilon_ = 0, alpha_ = 2, epsilon_final_ = 0, continuation_factor_ = 0.5;
  ObjectiveSpec objective_;
  double area_target_ = 0, area_fraction_ = 0, area_penalty_factor_ = 10;
  BoxField conductivity_{1, {}}, source_{1, {}}, neumann_{0, {}};
  TetrahedralizeOptions tetgen_;
  double volume_factor_ = 0;
  LinearSolverOptions solver_;
  double noise_given_ = -1, min_step_factor_ = 0.0625, max_dt_factor_ = 100;
  int volume_every_ = 0;
  bool sharp_ = true;  ///< J_sharp of every accepted state
  bool fixed_volume_ = false;  ///< volume_mesh = "fixed"
  int sharp_every_ = 1;
  int nucleation_every_ = 0;
  NucleationOptions nucleation_;  ///< radius and clearance resolved on T⁰ (saved in checkpoints)
  // State (saved in checkpoints).
  Descent descent_;          ///< the merit, the records of the accepted states, λ, the step bounds
  double alpha_length_ = 0;  ///< α·h
  double scatter_ = 0;       ///< measure_scatter on T⁰
  double speed_scale_ = 0;   ///< max |v| on T⁰: v is divided by it (or by its own max when larger)
  bool lengths_resolved_ = false;
  std::unique_ptr<FixedVolume> fixed_;            ///< volume_mesh = "fixed": built at the first state
  FaceMask fixed_neumann_;                         ///< Γ_N on S⁰
  std::optional<SurfaceMesh> resumed_surface_;     ///< S⁰ from a checkpoint
  std::vector<double> resumed_warm_start_;         ///< the solver's warm start from a checkpoint
  // Per step.
  std::shared_ptr<Evaluation> current_;  ///< u, p, J of T^n (the accepted candidate of the last step)
  double slope_ = 0;                     ///< J′(v) of the current descent speed
  struct {
    int count = 0;          ///< new components this attempt adds
    double predicted = 0;   ///< Σ ρ·g at their centres
  } nucleated_;
  std::unique_ptr<PvdWriter> volume_pvd_;
};

}  // namespace
}  // namespace bodyfit::thermal

BODYFIT_PLUGIN(bodyfit::thermal::ThermalModel)
