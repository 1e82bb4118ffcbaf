#include "objective.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <cmath>

namespace bodyfit::thermal {
namespace {

constexpr std::array<std::string_view, 4> kNames{"mean_temperature", "max_temperature", "region_mean", "dissipation"};

bool in_box(const std::array<double, 6>& box, const Vec3& x) {
  for (int k = 0; k < 3; ++k)
    if (x[k] < box[std::size_t(k)] || x[k] > box[std::size_t(k) + 3]) return false;
  return true;
}

/// ∫_B φ_i / |B| over the tetrahedra whose centroid lies in a box.
Eigen::VectorXd region_weights(const VolumeMesh& mesh, const std::vector<std::array<double, 6>>& boxes) {
  if (boxes.empty()) throw InputError("thermal objective region_mean: no box (set model.objective.boxes)");
  Eigen::VectorXd w = Eigen::VectorXd::Zero(Eigen::Index(mesh.n_vertices()));
  double volume = 0;
  for (const auto& t : mesh.tets) {
    const Vec3 &a = mesh.points[std::size_t(t[0])], &b = mesh.points[std::size_t(t[1])],
               &c = mesh.points[std::size_t(t[2])], &d = mesh.points[std::size_t(t[3])];
    const Vec3 centroid = (a + b + c + d) * 0.25;
    bool inside = false;
    for (const auto& box : boxes) inside = inside || in_box(box, centroid);
    if (!inside) continue;
    const double quarter = tet_volume(a, b, c, d) / 4;
    volume += 4 * quarter;
    for (int v : t) w[v] += quarter;
  }
  if (!(volume > 0))
    throw InputError(fmt::format("thermal objective region_mean: its {} box(es) contain no tetrahedron of the part "
                                 "(model.objective.boxes: is the region inside Ω?)",
                                 boxes.size()));
  return w / volume;
}

}  // namespace

std::string_view to_string(ObjectiveKind kind) { return kNames[std::size_t(kind)]; }

ObjectiveKind objective_kind_from_string(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) return ObjectiveKind(i);
  throw InputError(fmt::format("thermal objective: unknown kind '{}' (expected one of {})", name,
                               fmt::join(kNames, ", ")));
}

TemperatureFunctional::TemperatureFunctional(const VolumeMesh& mesh, const ObjectiveSpec& spec,
                                             const Eigen::SparseMatrix<double>& stiffness,
                                             const Eigen::VectorXd& volume_weights)
    : spec_(spec) {
  const double volume = volume_weights.sum();
  switch (spec.kind) {
    case ObjectiveKind::mean_temperature: weights_ = volume_weights / volume; break;
    case ObjectiveKind::max_temperature:
      if (!(spec.exponent >= 1) || !std::isfinite(spec.exponent))
        throw InputError(fmt::format("thermal objective max_temperature: exponent {} (expected ≥ 1)", spec.exponent));
      weights_ = volume_weights / volume;
      break;
    case ObjectiveKind::region_mean: weights_ = region_weights(mesh, spec.boxes); break;
    case ObjectiveKind::dissipation: stiffness_ = stiffness; break;
  }
}

bool TemperatureFunctional::linear() const {
  return spec_.kind == ObjectiveKind::mean_temperature || spec_.kind == ObjectiveKind::region_mean;
}

double TemperatureFunctional::value(const Eigen::VectorXd& u) const {
  switch (spec_.kind) {
    case ObjectiveKind::mean_temperature:
    case ObjectiveKind::region_mean: return weights_.dot(u);
    case ObjectiveKind::max_temperature: {
      // M·(Σ w_i (|u_i|/M)^q)^(1/q), M = max |u|: no overflow for a large q.
      const double q = spec_.exponent, top = u.cwiseAbs().maxCoeff();
      if (!(top > 0)) return 0;
      return top * std::pow(weights_.dot((u.cwiseAbs() / top).array().pow(q).matrix()), 1 / q);
    }
    case ObjectiveKind::dissipation: return u.dot(stiffness_ * u);
  }
  return 0;
}

Eigen::VectorXd TemperatureFunctional::gradient(const Eigen::VectorXd& u) const {
  switch (spec_.kind) {
    case ObjectiveKind::mean_temperature:
    case ObjectiveKind::region_mean: return weights_;
    case ObjectiveKind::max_temperature: {
      // j = m^(1/q), m = Σ w_i |u_i|^q: j′_i = j^(1−q) w_i |u_i|^(q−1) sign(u_i) = w_i (|u_i|/j)^(q−1) sign(u_i).
      const double q = spec_.exponent, j = value(u);
      if (!(j > 0)) return Eigen::VectorXd::Zero(u.size());
      const Eigen::ArrayXd a = u.array();
      return (weights_.array() * (a.abs() / j).pow(q - 1) * a.sign()).matrix();
    }
    case ObjectiveKind::dissipation: return 2 * (stiffness_ * u);
  }
  return {};
}

}  // namespace bodyfit::thermal
