#include "box_field.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>

namespace bodyfit::thermal {
namespace {

bool contains(const std::array<double, 7>& box, const Vec3& x) {
  for (int k = 0; k < 3; ++k)
    if (x[k] < box[std::size_t(k)] || x[k] > box[std::size_t(k) + 3]) return false;
  return true;
}

}  // namespace

double BoxField::operator()(const Vec3& x) const {
  double v = value;
  for (const auto& box : boxes)
    if (contains(box, x)) v = box[6];
  return v;
}

bool BoxField::inside_any(const Vec3& x) const {
  for (const auto& box : boxes)
    if (contains(box, x)) return true;
  return false;
}

BoxField read_box_field(Parameters& p, const std::string& key) {
  BoxField field;
  if (p.is_table(key)) {
    Parameters& t = p.section(key);
    field.value = t.number("value");
    const Range range = t.declaration("value")->range;
    for (const auto& box : t.points("boxes")) {
      std::array<double, 7> b{};
      std::copy(box.begin(), box.end(), b.begin());
      for (int k = 0; k < 3; ++k)
        if (!(b[std::size_t(k)] <= b[std::size_t(k) + 3]))
          t.fail("boxes", fmt::format("a box's min corner must not exceed its max corner (axis {})", "xyz"[k]));
      if (!range.contains(b[6])) t.fail("boxes", fmt::format("value {} is out of range {}", b[6], range.describe()));
      field.boxes.push_back(b);
    }
  } else {
    field.value = p.number(key);
  }
  return field;
}

}  // namespace bodyfit::thermal
