#pragma once
// The temperature functionals j(u) the thermal model can minimise, each with its derivative j′(u):
// the adjoint of J = j(u) solves (K + R) p = −j′(u), and the shape derivative keeps the form
// pᵀ(dR)u of shape_derivative.hpp whatever j is (only R depends on G).
//
//   mean_temperature   (1/|Ω|)∫_Ω u                                   linear
//   max_temperature    ((1/|Ω|)∫_Ω |u|^q)^(1/q), the lumped integral   an L^q approximation of max u
//   region_mean        (1/|B|)∫_B u, B the tetrahedra whose centroid   linear
//                      lies in one of the boxes
//   dissipation        ∫_Ω γ|∇u|² = uᵀ K_γ u                           quadratic
//
// Each is the exact value of the P1 u (or the lumped rule for max_temperature), and j′ the exact
// derivative of that discrete value: finite differences of J check the adjoint to round-off.
#include "volume_mesh.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <string_view>
#include <vector>

namespace bodyfit::thermal {

enum class ObjectiveKind { mean_temperature, max_temperature, region_mean, dissipation };

std::string_view to_string(ObjectiveKind kind);
/// The inverse of to_string; InputError listing the names otherwise.
ObjectiveKind objective_kind_from_string(std::string_view name);

struct ObjectiveSpec {
  ObjectiveKind kind = ObjectiveKind::mean_temperature;
  double exponent = 8;                       ///< q of max_temperature (≥ 1)
  std::vector<std::array<double, 6>> boxes;  ///< region_mean: [xmin, ymin, zmin, xmax, ymax, zmax]
};

/// j on one volume mesh. InputError for an exponent below 1, a region with no box or with no
/// tetrahedron of Ω in its boxes.
class TemperatureFunctional {
 public:
  /// `stiffness` is K_γ and `volume_weights` ∫φ_i on `mesh` (thermal_fem.hpp assembles both).
  TemperatureFunctional(const VolumeMesh& mesh, const ObjectiveSpec& spec, const Eigen::SparseMatrix<double>& stiffness,
                        const Eigen::VectorXd& volume_weights);

  double value(const Eigen::VectorXd& u) const;
  /// j′(u), one entry per volume vertex.
  Eigen::VectorXd gradient(const Eigen::VectorXd& u) const;
  /// j′ does not depend on u: the adjoint's right-hand side is known before the state is solved.
  bool linear() const;
  const ObjectiveSpec& spec() const { return spec_; }

 private:
  ObjectiveSpec spec_;
  Eigen::VectorXd weights_;               ///< linear kinds: j = weights_ᵀu; max_temperature: ∫φ_i / |Ω|
  Eigen::SparseMatrix<double> stiffness_; ///< dissipation only
};

}  // namespace bodyfit::thermal
