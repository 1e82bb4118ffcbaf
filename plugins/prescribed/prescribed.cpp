// Prescribed flows: a velocity given by a formula of position and time, for validation.
//
// flow = "nair_lauritzen": the deformational flows of Nair & Lauritzen (2010, J. Comput. Phys.
// 229, cases 1-4) on the sphere centred at the origin. In longitude λ and latitude θ, with
// T the period (their T = 5) and k the deformation strength, the eastward and northward
// components (in units of the radius R per unit time) are
//   case 1   u = k sin²(λ/2) sin(2θ) cos(πt/T)             v = (k/2) sin(λ) cos(θ) cos(πt/T)
//   case 2   u = k sin²(λ) sin(2θ) cos(πt/T)               v = k sin(2λ) cos(θ) cos(πt/T)
//   case 3   u = −k sin²(λ/2) sin(2θ) cos²(θ) cos(πt/T)    v = (k/2) sin(λ) cos³(θ) cos(πt/T)
//   case 4   u = k sin²(λ') sin(2θ) cos(πt/T) + 2π cos(θ)/T,  v = k sin(2λ') cos(θ) cos(πt/T),
//            λ' = λ − 2πt/T (the deformation of case 2 carried round by a solid-body rotation)
// Cases 1, 2 and 4 are non-divergent, case 3 is divergent. The deformation reverses at T/2 (and
// the rotation of case 4 makes one turn in T), so at t = T every point is back where it started:
// the region at T is the initial one. Default k: 2.4 (cases 1, 4), 2 (case 2), 1 (case 3), as in
// the paper and in Lauritzen et al. (2012, Geosci. Model Dev. 5) for case 4; `k` overrides it.
//
// The level set is transported by the flow, ∂φ/∂t + u·∇φ = 0. form = "vector" (default) returns u
// itself (tangent to the sphere): the characteristics are the flow's trajectories. form = "normal"
// returns the normal speed u·n_Σ (n_Σ the extended conormal), the same motion of the front written
// in bodyfit's normal-speed form (V = (u·n_Σ) n_Σ away from it). The field is evaluated at the
// middle of the step, t + Δt/2 (second order in time for a velocity frozen over the step).
#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace {

constexpr double kPi = std::numbers::pi;

class PrescribedModel final : public bodyfit::VelocityModel {
 public:
  std::string_view name() const override { return "prescribed"; }
  std::string_view version() const override { return "1.0"; }
  std::string_view description() const override {
    return "a velocity given by a formula: the deformational flows of Nair & Lauritzen (2010) on the sphere";
  }
  std::vector<bodyfit::ParameterDecl> parameters() const override {
    using bodyfit::ParameterDecl;
    return {ParameterDecl::choice("flow", {"nair_lauritzen"}, "the formula").fallback("nair_lauritzen"),
            ParameterDecl::integer("case", "", "Nair & Lauritzen's case: 1, 2, 4 (non-divergent) or 3 (divergent)")
                .fallback(4)
                .within({.min = 1, .max = 4}),
            ParameterDecl::number("period", "time", "T: the flow reverses at T/2 and is back at the start at T")
                .fallback(5.0)
                .positive(),
            ParameterDecl::number("k", "", "deformation strength").computed("2.4 for cases 1 and 4, 2 for case 2, 1 for case 3"),
            ParameterDecl::choice("form", {"vector", "normal"}, "vector: V = u; normal: the normal speed u·n_Σ")
                .fallback("vector")};
  }

  std::vector<bodyfit::OutputDecl> outputs() const override {
    return {bodyfit::OutputDecl::metric("time_factor", "1", "cos(πt/T) at the middle of the step: the flow's reversal"),
            bodyfit::OutputDecl::vertex_field("flow", "length/time", "the prescribed velocity u (a vector)")};
  }

  void configure(bodyfit::Parameters& p) override {
    p.choice("flow");
    case_ = int(p.integer("case"));
    period_ = p.number("period");
    const double default_k = case_ == 2 ? 2.0 : case_ == 3 ? 1.0 : 2.4;
    k_ = p.number("k", default_k);
    normal_form_ = p.choice("form") == "normal";
  }

  bodyfit::VelocityField compute(const bodyfit::StepContext& context) override {
    const auto& mesh = context.mesh();
    const double t = context.time() + 0.5 * context.dt();
    bodyfit::VectorField u(mesh.n_vertices(), bodyfit::Vec3(0, 0, 0));
    for (auto v : mesh.vertices()) u[v.idx()] = flow(mesh.point(v), t);
    bodyfit::VelocityField field;
    if (normal_form_) {
      const bodyfit::VectorField& n = context.conormal();
      bodyfit::ScalarField speed(u.size());
      for (std::size_t i = 0; i < u.size(); ++i) speed[i] = OpenMesh::dot(u[i], n[i]);
      field = bodyfit::VelocityField::normal(std::move(speed));
    } else {
      field = bodyfit::VelocityField::tangential(u);
    }
    field.metrics.emplace_back("time_factor", std::cos(kPi * t / period_));
    field.vector_fields.emplace_back("flow", std::move(u));
    return field;
  }

 private:
  /// The flow at point p (on the sphere of radius |p| about the origin) at time t.
  bodyfit::Vec3 flow(const bodyfit::Vec3& p, double t) const {
    const double radius = p.norm();
    if (!(radius > 0)) return {0, 0, 0};
    const double rho = std::hypot(p[0], p[1]);
    const double lambda = std::atan2(p[1], p[0]), theta = std::atan2(p[2], rho);
    const double c = std::cos(kPi * t / period_), cos_theta = std::cos(theta);
    double east = 0, north = 0;
    switch (case_) {
      case 1:
        east = k_ * std::pow(std::sin(lambda / 2), 2) * std::sin(2 * theta) * c;
        north = 0.5 * k_ * std::sin(lambda) * cos_theta * c;
        break;
      case 2:
        east = k_ * std::pow(std::sin(lambda), 2) * std::sin(2 * theta) * c;
        north = k_ * std::sin(2 * lambda) * cos_theta * c;
        break;
      case 3:
        east = -k_ * std::pow(std::sin(lambda / 2), 2) * std::sin(2 * theta) * cos_theta * cos_theta * c;
        north = 0.5 * k_ * std::sin(lambda) * std::pow(cos_theta, 3) * c;
        break;
      default: {
        const double shifted = lambda - 2 * kPi * t / period_;
        east = k_ * std::pow(std::sin(shifted), 2) * std::sin(2 * theta) * c + 2 * kPi * cos_theta / period_;
        north = k_ * std::sin(2 * shifted) * cos_theta * c;
      }
    }
    // Unit east and north vectors; at the poles (rho = 0) u is zero or along a direction the
    // formulas leave undefined: the flows above vanish there except case 4's rotation term, whose
    // cos θ factor vanishes too.
    if (!(rho > 1e-12 * radius)) return {0, 0, 0};
    const bodyfit::Vec3 e_east(-p[1] / rho, p[0] / rho, 0);
    const bodyfit::Vec3 e_north(-p[2] * p[0] / (rho * radius), -p[2] * p[1] / (rho * radius), rho / radius);
    return radius * (east * e_east + north * e_north);
  }

  int case_ = 4;
  double period_ = 5.0;
  double k_ = 2.4;
  bool normal_form_ = false;
};

}  // namespace

BODYFIT_PLUGIN(PrescribedModel)
