// The conormal velocity of the paper's first example, (4.1): V = ∇_S d_{G(t)}.
//
// ∇_S d is the unit conormal n_Σ on the interface ∂G (pointing out of G) and extends it to the
// whole surface as the gradient of the signed distance, so G grows at unit normal speed along the
// geodesics normal to its boundary. `speed` scales it (a negative speed shrinks G).
//
// With `period` P > 0 the speed oscillates: V = speed·cos(2πt/P + phase)·∇_S d, so the front goes
// out and back and a cap of polar angle a0 on the unit sphere has the exact polar angle
//     a(t) = a0 + speed·P/(2π)·(sin(2πt/P + phase) − sin(phase)),
// periodic in t (the drift test; bench/bench_drift, bench/bench_soak). The factor applied
// over a step [t, t + Δt] is the mean of cos over it, so that a step moves a front at uniform
// speed by the exact distance whatever Δt (with CFL sub-steps: the mean over what remains of the
// step).
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace {

class ConormalModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "conormal"; }
  std::string_view version() const override { return "1.0"; }
  std::string_view description() const override {
    return "V = speed * grad_S d: the unit conormal extended by the gradient of the signed distance (paper (4.1))";
  }
  std::vector<bodyfit::ParameterDecl> parameters() const override {
    using bodyfit::ParameterDecl;
    return {ParameterDecl::number("speed", "length/time", "factor multiplying V; a negative value shrinks G").fallback(1.0),
            ParameterDecl::number("period", "time", "period P of an oscillating speed speed·cos(2πt/P + phase); 0: a "
                                                    "constant speed")
                .fallback(0.0)
                .at_least(0),
            ParameterDecl::number("phase", "degrees", "phase of the oscillation (with a period)").fallback(0.0)};
  }
  std::vector<bodyfit::OutputDecl> outputs() const override {
    return {bodyfit::OutputDecl::metric("speed", "length/time", "the factor of the step (speed × the mean of the "
                                                                "oscillation over it)")};
  }
  void configure(bodyfit::Parameters& p) override {
    speed_ = p.number("speed");
    period_ = p.number("period");
    if (period_ > 0) phase_ = p.number("phase") * std::numbers::pi / 180;
    else p.not_used("phase", "it applies only with a period > 0");
  }
  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    const double factor = speed_ * oscillation(context.time(), context.dt());
    bodyfit::VectorField v = context.conormal();
    for (auto& x : v) x *= factor;
    auto field = bodyfit::VelocityField::tangential(std::move(v));
    field.metrics.emplace_back("speed", factor);
    return field;
  }

 private:
  /// The mean of cos(ωτ + phase) over [t, t + dt] (1 without a period).
  double oscillation(double t, double dt) const {
    if (period_ == 0) return 1.0;
    const double omega = 2 * std::numbers::pi / period_;
    if (!(dt > 0)) return std::cos(omega * t + phase_);
    // sin(b) − sin(a) = 2 cos((a + b)/2) sin((b − a)/2): no cancellation for a small dt.
    const double half = 0.5 * omega * dt;
    return std::cos(omega * (t + 0.5 * dt) + phase_) * std::sin(half) / half;
  }

  double speed_ = 1.0;
  double period_ = 0.0;  ///< 0: constant speed
  double phase_ = 0.0;   ///< radians
};

}  // namespace

BODYFIT_PLUGIN(ConormalModel)
