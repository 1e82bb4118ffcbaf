// The thermal shape-optimisation model (paper §4.4) as a bodyfit plugin. S = ∂Ω is the skin of a
// part; G ⊂ S is held at temperature 0 through the Robin coefficient h_ε(d_G). The model moves G
// along a descent direction of J_ε(G) = T_ε(G) + ℓ|G| (docs/reference/thermal_model.md):
//
//   compute(T^n)   tetrahedralise Ω (TetGen, S kept), solve the state u and the adjoint p (one
//                  CHOLMOD factorisation), w = −(1/ε²) h′(d/ε) u p on S, then the descent normal
//                  speed v: (M + α²K) v = −(M w + ℓ b_Σ), zero on Γ_N, normalised to max |v| = 1;
//   review(T^{n+1}) J on the candidate; Armijo: J^{n+1} ≤ J^n + c·Δt·J′(v) or the step is rejected
//                  (the driver retries with Δt/2; a step still raising J at the shortest length is a
//                  jump of the discretisation and is taken); after a success Δt grows (×grow,
//                  capped); the run stops when the best J improves by less than `tolerance` over
//                  `patience` accepted steps. The candidate's solution serves the next compute().
//   state          the objective history, ε and α as resolved, Δt's cap.
#include "box_field.hpp"
#include "shape_derivative.hpp"
#include "sharp_problem.hpp"
#include "smoothing.hpp"
#include "thermal_fem.hpp"
#include "volume_mesh.hpp"
#include "volume_vtu.hpp"

#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <Eigen/SparseCholesky>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

namespace bodyfit::thermal {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// Everything computed on one state (T^n or a candidate): its volume mesh, u, p and J.
struct Evaluation {
  int iteration = -1;  ///< the state it belongs to
  VolumeMesh volume;
  ThermalSolution solution;
  ThermalObjective objective;
  double interface_length = 0;  ///< |Σ| = ∫_Σ dℓ
  double ms_tetrahedralize = 0;
};

class ThermalModel final : public VelocityModel {
 public:
  std::string_view name() const override { return "thermal"; }
  std::string_view version() const override { return "1.0"; }
  std::string_view description() const override {
    return "shape optimisation of the region G of a part's skin held at temperature 0: descent of "
           "J = mean temperature + ell*|G| (paper §4.4; TetGen + P1 FEM + CHOLMOD)";
  }

  std::vector<ParameterDecl> parameters() const override {
    const Range positive{.min = 0, .min_exclusive = true};
    return {
        ParameterDecl::number("ell", "temperature/area", "weight ℓ of the area |G| in J").fallback(0.01).at_least(0),
        ParameterDecl::number("epsilon", "length", "half-width ε of the smoothed Dirichlet band")
            .computed("3 × the mean edge of T^0")
            .positive(),
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
        ParameterDecl::number("armijo", "1", "sufficient decrease: J(new) ≤ J + armijo·Δt·J′(v) + noise·|J|, else the step "
                                             "is rejected")
            .fallback(1e-4)
            .within({.min = 0, .max = 1, .max_exclusive = true}),
        ParameterDecl::number("noise", "1", "relative increase of J tolerated for the remeshing and tetrahedralisation "
                                            "noise of the discrete J")
            .fallback(0.01)
            .within({.min = 0, .max = 1}),
        ParameterDecl::number("min_step_factor", "1", "a step shorter than this × the case's Δt that still raises J is "
                                                      "taken anyway (a jump of the discretisation, not an ascent)")
            .fallback(0.0625)
            .within({.min = 0, .max = 1}),
        ParameterDecl::number("grow", "1", "Δt is multiplied by this after an accepted step").fallback(1.2).at_least(1),
        ParameterDecl::number("max_dt_factor", "1", "cap on Δt, as a multiple of the case's Δt").fallback(4.0).at_least(1),
        ParameterDecl::number("tolerance", "1", "converged when the best J improves by less than this (relative) over "
                                                "`patience` accepted steps")
            .fallback(1e-3)
            .at_least(0),
        ParameterDecl::integer("patience", "steps", "see tolerance").fallback(15).within({.min = 1, .max = 1000000}),
        ParameterDecl::boolean("sharp", "solve the sharp problem (4.12) on every accepted state's volume mesh "
                                        "and report J_sharp (one more solve)")
            .fallback(true),
        ParameterDecl::integer("volume_every", "states", "write volume_NNNNN.vtu (tetrahedra with u) every k states (0: "
                                                         "never)")
            .fallback(0)
            .within({.min = 0, .max = 1000000}),
    };
  }

  std::vector<OutputDecl> outputs() const override {
    return {OutputDecl::metric("slope", "temperature/time", "J′(v): the derivative of J along the descent speed"),
            OutputDecl::metric("ms_regularise", "ms", "the H¹ regularisation's solve"),
            OutputDecl::metric("J", "temperature", "the objective of the accepted state"),
            OutputDecl::metric("forced", "1", "1 when the step was taken although it raised J"),
            OutputDecl::metric("T", "temperature", "mean temperature over the part"),
            OutputDecl::metric("area_G", "area", "|G|"),
            OutputDecl::metric("length_Sigma", "length", "|∂G|"),
            OutputDecl::metric("decrease", "1", "relative decrease of J over the step"),
            OutputDecl::metric("step", "time", "the step taken"),
            OutputDecl::metric("tets", "1", "tetrahedra of the volume mesh"),
            OutputDecl::metric("ms_tetgen", "ms", "tetrahedralisation"),
            OutputDecl::metric("ms_assembly", "ms", "set-up and assembly"),
            OutputDecl::metric("ms_factor", "ms", "analysis and factorisation"),
            OutputDecl::metric("ms_solve", "ms", "solves"),
            OutputDecl::metric("T_sharp", "temperature", "the mean temperature of the sharp problem (4.12): u = 0 on "
                                                         "G's faces (sharp = true)"),
            OutputDecl::metric("J_sharp", "temperature", "T_sharp + ell·|G|: the objective J_ε approximates"),
            OutputDecl::metric("ms_sharp", "ms", "the sharp problem's assembly and solve"),
            OutputDecl::vertex_field("temperature", "temperature", "u at the surface's vertices"),
            OutputDecl::vertex_field("adjoint", "", "p at the surface's vertices"),
            OutputDecl::vertex_field("shape_gradient", "", "the density w of J′ on the surface"),
            OutputDecl::vertex_field("descent_speed", "1", "v, the normal speed of the descent (max |v| = 1)"),
            OutputDecl::file("objective.csv", "J of every accepted state from T^0"),
            OutputDecl::file("volume.pvd", "the series of volume_NNNNN.vtu (with volume_every)")};
  }

  void configure(Parameters& p) override {
    ell_ = p.number("ell");
    epsilon_ = p.number("epsilon", 0);
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
    armijo_ = p.number("armijo");
    noise_ = p.number("noise");
    min_step_factor_ = p.number("min_step_factor");
    grow_ = p.number("grow");
    max_dt_factor_ = p.number("max_dt_factor");
    tolerance_ = p.number("tolerance");
    patience_ = int(p.integer("patience"));
    volume_every_ = int(p.integer("volume_every"));
    sharp_ = p.boolean("sharp");
  }

  ModelNeeds needs() const override { return {.may_reject = true, .freeze_velocity = true}; }

  VelocityField compute(const StepContext& context) override {
    const SurfaceMesh& mesh = context.mesh();
    resolve_lengths(context);
    if (!current_ || current_->iteration != context.iteration()) current_ = evaluate(context);
    const Evaluation& e = *current_;

    // The descent speed: (M + α²K) v = −(M w + ℓ b_Σ), b_Σ the interface's line load, zero on Γ_N.
    const auto start = std::chrono::steady_clock::now();
    const Eigen::Map<const Eigen::VectorXd> w(e.objective.density.data(), Eigen::Index(mesh.n_vertices()));
    Eigen::VectorXd rhs = context.mass_matrix() * w + ell_ * interface_load(mesh);
    Eigen::SparseMatrix<double> system = context.mass_matrix() + (alpha_length_ * alpha_length_) * context.stiffness_matrix();
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system);
    if (ldlt.info() != Eigen::Success) throw InputError("thermal: the H¹ regularisation system is singular");
    Eigen::VectorXd v = -ldlt.solve(rhs);
    const std::vector<char> fixed = neumann_vertices(mesh);
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (fixed[std::size_t(i)]) v[i] = 0;
    const double largest = v.cwiseAbs().maxCoeff();
    if (largest > 0) v /= largest;
    slope_ = rhs.dot(v);  // J′(v) = ∫ w v + ℓ∫_Σ v  (< 0: a descent direction)
    ms_velocity_ = ms_since(start);
    if (dt0_ == 0) dt0_ = context.dt();
    if (history_.empty()) {
      history_.push_back(e.objective.J);
      spdlog::info("thermal: J = {:.8g} (T = {:.8g}, |G| = {:.6g}) on T^{}, {} tetrahedra, eps = {:.4g}, alpha = {:.4g}",
                   e.objective.J, e.objective.T, e.objective.area, context.iteration(), e.volume.n_tets(), epsilon_,
                   alpha_length_);
    }

    ScalarField speed(v.data(), v.data() + v.size());
    VelocityField field = VelocityField::normal(speed);
    field.metrics = {{"slope", slope_}, {"ms_regularise", ms_velocity_}};
    const auto n = std::size_t(e.volume.n_surface_vertices);
    field.point_fields = {{"temperature", ScalarField(e.solution.u.data(), e.solution.u.data() + n)},
                          {"adjoint", ScalarField(e.solution.p.data(), e.solution.p.data() + n)},
                          {"shape_gradient", e.objective.density},
                          {"descent_speed", speed}};
    return field;
  }

  Review review(const StepContext& candidate, int /*attempt*/) override {
    const double J = current_->objective.J;
    std::shared_ptr<Evaluation> next;
    try {
      next = evaluate(candidate);
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
    const double J_next = next->objective.J;
    // Armijo's sufficient decrease, up to the noise of the discrete J: two meshes of the same G
    // (remeshed, tetrahedralised anew) give J values that differ by a fraction of a percent.
    const double bound = J + armijo_ * candidate.dt() * slope_ + noise_ * std::abs(J);
    bool forced = false;
    if (!(J_next <= bound)) {
      const std::string why =
          fmt::format("J = {:.8g} > {:.8g} (J^n = {:.8g}, Armijo with noise {:g}, dt = {:.4g}; |G| {:.5g} -> {:.5g})",
                      J_next, bound, J, noise_, candidate.dt(), current_->objective.area, next->objective.area);
      if (candidate.dt() >= min_step_factor_ * dt0_ * (1 - 1e-12)) return Review::reject(why);
      // Even the shortest step raises J: not an ascent direction but a jump of the discretisation —
      // a part of G thinner than an element that no P1 level set can carry is lost in the cut,
      // whatever the step. Take the step and go on from there; `patience` still ends a run that
      // only stagnates.
      spdlog::warn("thermal, step {}: the shortest step still raises J ({}); taken", candidate.iteration(), why);
      forced = true;
    }
    const double decrease = (J - J_next) / std::abs(J);
    history_.push_back(J_next);
    write_volume(*next, candidate);
    const ThermalObjective& o = next->objective;
    const ThermalTimings& t = next->solution.timings;
    // The true objective beside the smoothed one: u = 0 on G's faces of the same volume mesh.
    double T_sharp = std::numeric_limits<double>::quiet_NaN(), ms_sharp = 0;
    if (sharp_) {
      FaceMask g(candidate.mesh().n_faces(), 0);
      for (auto f : candidate.mesh().faces()) g[std::size_t(f.idx())] = candidate.mesh().inside(f);
      ThermalProblem problem = base_problem(candidate.mesh());
      try {
        const SharpSolution sharp = solve_sharp(next->volume, problem, g, solver_);
        T_sharp = sharp.mean_temperature;
        ms_sharp = sharp.ms;
      } catch (const InputError& error) {
        spdlog::warn("thermal, step {}: no sharp J ({})", candidate.iteration(), error.what());
      }
    }
    Review r = converged() ? Review::accept_and_stop(fmt::format(
                                 "converged: the best J improved by less than {:g} (relative) over the last {} steps "
                                 "(J = {:.8g}, best {:.8g})",
                                 tolerance_, patience_, J_next, *std::min_element(history_.begin(), history_.end())))
                           : Review::accept();
    r.next_dt = std::min(candidate.dt() * grow_, max_dt_factor_ * dt0_);
    r.metrics = {{"J", o.J},
                 {"forced", forced ? 1.0 : 0.0},
                 {"T", o.T},
                 {"area_G", o.area},
                 {"length_Sigma", next->interface_length},
                 {"decrease", decrease},
                 {"step", candidate.dt()},
                 {"tets", double(next->volume.n_tets())},
                 {"ms_tetgen", next->ms_tetrahedralize},
                 {"ms_assembly", t.setup_ms + t.assembly_ms},
                 {"ms_factor", t.analysis_ms + t.factorization_ms},
                 {"ms_solve", t.solve_ms},
                 {"T_sharp", T_sharp},
                 {"J_sharp", T_sharp + ell_ * o.area},
                 {"ms_sharp", ms_sharp}};
    current_ = std::move(next);  // T^{n+1} is the next compute's state
    return r;
  }

  /// The best J of the last `patience` states is within `tolerance` of the best before them: J only
  /// fluctuates (by the noise of its discretisation) without improving any more.
  bool converged() const {
    const std::size_t k = std::size_t(patience_);
    if (history_.size() <= k + 1) return false;
    const auto recent = history_.end() - std::ptrdiff_t(k);
    const double best_before = *std::min_element(history_.begin(), recent);
    const double best_recent = *std::min_element(recent, history_.end());
    return best_recent >= best_before - tolerance_ * std::abs(best_before);
  }

  /// objective.csv: J of every accepted state from T^0 (history.csv's J starts at row 1, the first
  /// state a review measured).
  void finish(const StepContext& final_state, ModelOutputs& /*outputs*/) override {
    const std::filesystem::path& output_dir = final_state.output_dir();
    if (output_dir.empty() || history_.empty()) return;
    write_atomically(output_dir / "objective.csv", [&](std::ostream& out) {
      out << "state,J\n";
      for (std::size_t i = 0; i < history_.size(); ++i) out << fmt::format("{},{:.17g}\n", i, history_[i]);
    });
  }

  void save_state(ModelState& state) const override {
    state.version = 1;
    state.set("objective", history_);
    state.set("lengths", std::vector<double>{epsilon_, alpha_length_, dt0_});
  }

  void load_state(const ModelState& state) override {
    if (state.version != 1)
      throw InputError(fmt::format("thermal model state version {} (this plugin reads version 1)", state.version));
    history_ = state.numbers("objective");
    const auto& lengths = state.numbers("lengths");
    if (lengths.size() != 3) throw InputError("thermal model state: 'lengths' needs 3 numbers");
    epsilon_ = lengths[0], alpha_length_ = lengths[1], dt0_ = lengths[2];
    lengths_resolved_ = true;
  }

 private:
  /// ε and α·h from the first mesh (kept in the state, so a resumed run uses the same).
  void resolve_lengths(const StepContext& context) {
    if (lengths_resolved_) return;
    const double h = context.mesh_size();
    if (!(epsilon_ > 0)) epsilon_ = 3 * h;
    alpha_length_ = alpha_ * h;
    lengths_resolved_ = true;
  }

  std::shared_ptr<Evaluation> evaluate(const StepContext& context) const {
    auto e = std::make_shared<Evaluation>();
    e->iteration = context.iteration();
    const SurfaceMesh& mesh = context.mesh();
    auto start = std::chrono::steady_clock::now();
    TetrahedralizeOptions tetgen = tetgen_;
    if (volume_factor_ > 0) tetgen.max_volume = volume_factor_ * regular_tet_volume(context.mesh_size());
    try {
      e->volume = tetrahedralize(mesh, tetgen);
    } catch (const InputError& error) {
      throw InputError(fmt::format("thermal, iteration {}: {}", context.iteration(), error.what()));
    }
    e->ms_tetrahedralize = ms_since(start);

    ThermalProblem problem = base_problem(mesh);
    problem.robin_field = context.distance();
    const double epsilon = epsilon_;
    problem.robin_coefficient = [epsilon](double d) { return h_epsilon(d, epsilon); };
    const FaceMask neumann = problem.neumann;
    ThermalOptions options;
    options.linear = solver_;
    try {
      e->solution = solve_thermal(e->volume, problem, options);
    } catch (const InputError& error) {
      throw InputError(fmt::format("thermal, iteration {}: {}", context.iteration(), error.what()));
    }
    ObjectiveOptions objective{.epsilon = epsilon_, .ell = ell_, .quadrature = options.quadrature, .neumann = neumann};
    e->objective = thermal_objective(mesh, context.distance(), e->solution, objective);
    for (auto edge : mesh.edges())
      if (mesh.interface(edge)) e->interface_length += mesh.calc_edge_length(edge);
    return e;
  }

  /// The part's conductivity, source and Neumann boxes on `mesh` (the smoothed problem adds its
  /// Robin term, the sharp one holds G at 0).
  ThermalProblem base_problem(const SurfaceMesh& mesh) const {
    ThermalProblem problem;
    if (!conductivity_.constant() || conductivity_.value != 1) problem.conductivity = conductivity_;
    if (!source_.constant() || source_.value != 1) problem.source = source_;
    const FaceMask neumann = neumann_faces(mesh);
    if (!neumann.empty()) {
      problem.neumann = neumann;
      problem.neumann_flux = neumann_;  // g: a box's value on its faces
    }
    return problem;
  }

  /// b_Σ = ∫_Σ φ_i dℓ: half of each interface edge's length to each of its ends.
  static Eigen::VectorXd interface_load(const SurfaceMesh& mesh) {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(Eigen::Index(mesh.n_vertices()));
    for (auto e : mesh.edges()) {
      if (!mesh.interface(e)) continue;
      const double half = 0.5 * mesh.calc_edge_length(e);
      const auto h = mesh.halfedge_handle(e, 0);
      b[mesh.to_vertex_handle(h).idx()] += half;
      b[mesh.from_vertex_handle(h).idx()] += half;
    }
    return b;
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
    write_volume_vtu(e.volume, {{"temperature", &e.solution.u}, {"adjoint", &e.solution.p}}, candidate.output_dir() / name);
    if (!volume_pvd_)
      volume_pvd_ = std::make_unique<PvdWriter>(
          PvdWriter::resume(candidate.output_dir() / "volume.pvd", candidate.time() - 0.5 * candidate.dt()));
    volume_pvd_->add(candidate.time(), name);
  }

  // Parameters.
  double ell_ = 0.01, epsilon_ = 0, alpha_ = 2;
  BoxField conductivity_{1, {}}, source_{1, {}}, neumann_{0, {}};
  TetrahedralizeOptions tetgen_;
  double volume_factor_ = 0;
  LinearSolverOptions solver_;
  double armijo_ = 1e-4, noise_ = 0.01, min_step_factor_ = 0.0625, grow_ = 1.2, max_dt_factor_ = 4, tolerance_ = 1e-3;
  int patience_ = 15, volume_every_ = 0;
  bool sharp_ = true;  ///< J_sharp of every accepted state
  // State (saved in checkpoints).
  std::vector<double> history_;  ///< J of every accepted state, from T^0
  double alpha_length_ = 0;      ///< α·h
  double dt0_ = 0;               ///< the first step, for the cap on Δt
  bool lengths_resolved_ = false;
  // Per step.
  std::shared_ptr<Evaluation> current_;  ///< u, p, J of T^n (the accepted candidate of the last step)
  double slope_ = 0;                     ///< J′(v) of the current descent speed
  double ms_velocity_ = 0;
  std::unique_ptr<PvdWriter> volume_pvd_;
};

}  // namespace
}  // namespace bodyfit::thermal

BODYFIT_PLUGIN(bodyfit::thermal::ThermalModel)
