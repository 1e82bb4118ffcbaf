#pragma once
// The thermal model's descent: the merit function with its area term, the sufficient-decrease test
// of a candidate, the next step length and the stops. Pure bookkeeping on numbers (no mesh), so each
// rule is tested on its own.
//
//   merit       M(G) = j(G) + ℓ|G| + λ(|G| − A) + (μ/2)(|G| − A)²   (the last two with a target area A:
//               an augmented Lagrangian of the constraint |G| = A; λ ← λ + μ(|G| − A) every
//               `update_every` accepted steps)
//   its slope   M′(θ) = ∫_S w θ·n + ℓ_eff ∫_Σ θ·n,  ℓ_eff = ℓ + λ + μ(|G| − A)
//   accept      M(candidate) ≤ M + armijo·Δt·M′(v) + noise·|M|, noise the relative scatter of j
//               between two meshes of one G (measured by the model at T⁰); raised to twice the rise
//               of a rejected retry whose deviation from the first-order model, M(candidate) − M −
//               Δt·M′(v), did not fall below half the previous attempt's when Δt was halved (a
//               second-order term would fall to a quarter: what stays is the noise of the step's
//               cut, remesh and tetrahedralisation), up to max_noise
//   next Δt     a trust region on the front's motion Δt·max|v|: the region grows (×grow, up to
//               max_motion; the model sets h and ε/2) after a step that lowered M at its first
//               attempt, and shrinks to the motion taken after a rejection, to half of it after a
//               step that raised M (accepted within the noise); Δt = region / max|v|, within
//               [min_step, max_step]
//   stop        stationary: |M′(v)| ≤ stationarity·|M′(v⁰)| (and, with a target, |G| within
//               area_tolerance of A); or stalled: the best merit improved by less than
//               max(tolerance, noise) over `patience` accepted steps
#include <optional>
#include <string>
#include <vector>

namespace bodyfit::thermal {

struct DescentOptions {
  double ell = 0;                  ///< weight of |G|
  double armijo = 1e-4;            ///< sufficient-decrease constant
  double noise = 0;                ///< relative noise of j tolerated by the sufficient-decrease test
  double max_noise = 0.01;         ///< the most the noise may grow to from the steps' rises
  /// A step whose front motion Δt·max|v| is this short or shorter and still raises M is taken
  /// (forced: a jump of the discretisation); also the shortest Δt the trust region gives.
  double min_step = 0;
  double grow = 1.2;               ///< Δt factor after a step accepted at once
  double max_step = 0;             ///< cap on Δt (0: none)
  double max_motion = 0;           ///< cap on Δt·max|v|, the front's largest motion in a step (0: none)
  double tolerance = 1e-3;         ///< stall: relative improvement of the best merit over `patience` steps
  int patience = 15;
  double stationarity = 0.005;     ///< stop when |M′| falls to this fraction of its first value (0: never)
  std::optional<double> target;    ///< A: the area G is held to (augmented Lagrangian)
  double penalty = 0;              ///< μ (merit per area²)
  int update_every = 5;            ///< accepted steps between updates of λ
  double area_tolerance = 0.005;   ///< |(|G| − A)| ≤ this × A for a stationary stop
};

/// One accepted state.
struct DescentRecord {
  double j = 0, area = 0, slope = 0;
  int stage = 0;  ///< the continuation stage (the merit of one stage is not that of another: ε differs)
};

class Descent {
 public:
  Descent() = default;
  explicit Descent(DescentOptions options) : options_(std::move(options)) {}

  const DescentOptions& options() const { return options_; }
  DescentOptions& options() { return options_; }
  double lambda() const { return lambda_; }
  void set_lambda(double lambda) { lambda_ = lambda; }

  double merit(double j, double area) const;
  /// ℓ_eff: the weight of ∫_Σ θ·n in the slope at a state of area `area`.
  double area_weight(double area) const;

  /// The verdict on a candidate of merit ingredients (j, area), reached from the current state
  /// (current_j, current_area) with the step `dt` along a direction of slope `slope` (< 0).
  struct Verdict {
    bool accept = false, forced = false;
    double bound = 0;  ///< the largest merit accepted
  };
  /// `attempt`: 0 for a step's first try, 1, 2… after rejections; `speed`: max|v| of the direction.
  /// A rejected retry whose deviation from the first-order model did not shrink raises
  /// options().noise (see above).
  Verdict judge(double current_j, double current_area, double slope, double dt, double speed, double j, double area,
                int attempt);

  /// Record an accepted state (the slope is that of the direction computed on it, filled in by
  /// set_slope when it is known); updates λ every update_every records.
  void accept(double j, double area);
  /// The slope M′(v) of the direction computed on the last recorded state.
  void set_slope(double slope);
  /// After an accepted step of length dt taken along a direction of largest speed `speed` at
  /// attempt `attempt` (0: first try), which raised M when `rose`: the trust region's update and
  /// the next Δt for a direction of largest speed `next_speed`.
  double next_step(double dt, double speed, int attempt, bool rose, double next_speed);
  /// The first Δt of a stage: the whole trust region, max_motion / next_speed, within the bounds.
  double stage_step(double next_speed) const;
  /// The trust region's radius (0 until the first step: max_motion).
  double motion() const { return motion_; }
  void set_motion(double motion) { motion_ = motion; }
  /// Why the run should stop after the last record, or "" to go on. Only the current stage's
  /// records count.
  std::string stop_reason() const;
  /// A new stage (the merit changed: a smaller ε) starting from the state (j, area): it replaces
  /// the last record's values in the new stage; the stops and the trust region start again.
  void new_stage(double j, double area);
  int stage() const { return records_.empty() ? 0 : records_.back().stage; }

  const std::vector<DescentRecord>& records() const { return records_; }
  void set_records(std::vector<DescentRecord> records) { records_ = std::move(records); }

 private:
  DescentOptions options_;
  double lambda_ = 0;
  double motion_ = 0;
  double last_deviation_ = 0;  ///< of the last rejected attempt of this step (0: none)
  std::vector<DescentRecord> records_;  ///< every accepted state from T⁰
};

}  // namespace bodyfit::thermal
