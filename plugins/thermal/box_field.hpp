#pragma once
// BoxField: a piecewise-constant function of position read from a case — a default value and
// axis-aligned boxes with their own values (the last box containing a point wins). It is how a
// case gives the conductivity γ, the source f and the Neumann part Γ_N of the thermal model:
//
//   [model.conductivity]
//   value = 1.0
//   boxes = [[xmin, ymin, zmin, xmax, ymax, zmax, value], ...]
//
// or simply `conductivity = 2.5` for a constant.
#include <bodyfit/mesh.hpp>
#include <bodyfit/parameters.hpp>

#include <array>
#include <string>
#include <vector>

namespace bodyfit::thermal {

struct BoxField {
  double value = 0;                              ///< outside every box
  std::vector<std::array<double, 7>> boxes;      ///< min corner, max corner, value
  bool constant() const { return boxes.empty(); }
  double operator()(const Vec3& x) const;
  /// Whether x is in any box (for masks such as Γ_N).
  bool inside_any(const Vec3& x) const;
};

/// Read `key` through `p`: a number, or a table with `value` and `boxes` (declared as key,
/// key.value and key.boxes); the declared default when absent. The declared range of key.value
/// applies to the boxes' values too.
BoxField read_box_field(Parameters& p, const std::string& key);

}  // namespace bodyfit::thermal
