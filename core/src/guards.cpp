// The shared entry-point checks (guards.hpp): face budget, remesh options, finiteness.
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/remesh.hpp>

#include <fmt/format.h>

#include <atomic>
#include <cmath>
#include <limits>

#include <unistd.h>

namespace bodyfit {
namespace {

std::atomic<std::size_t>& limit() {
  static std::atomic<std::size_t> faces{default_max_faces()};
  return faces;
}

/// "2.8 TB", "650 MB": a size in bytes for messages.
std::string format_bytes(double bytes) {
  const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (bytes >= 1000 && u < 6) bytes /= 1000, ++u;
  if (bytes >= 1000) return fmt::format("{:.2g} EB", bytes);
  return fmt::format("{:.3g} {}", bytes, units[u]);
}

}  // namespace

std::size_t default_max_faces() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  // Unknown memory: the budget of an 8 GB machine.
  const double memory = pages > 0 && page > 0 ? double(pages) * double(page) : 8e9;
  return std::size_t(0.75 * memory / kBytesPerFace);
}

std::size_t max_faces() { return limit().load(std::memory_order_relaxed); }

void set_max_faces(std::size_t faces) { limit().store(faces, std::memory_order_relaxed); }

void check_face_budget(double estimated_faces, std::string_view what) {
  const std::size_t cap = max_faces();
  if (cap == 0 && !std::isnan(estimated_faces)) return;
  if (std::isnan(estimated_faces))
    throw InputError(fmt::format("{}: the size of the mesh cannot be estimated (a NaN size)", what));
  if (estimated_faces <= double(cap)) return;
  throw InputError(fmt::format(
      "{}: about {:.3g} faces (about {} at {:.0f} bytes per face), above the limit of {} faces (3/4 of this "
      "machine's memory by default); raise it with `bodyfit --max-faces N` (0: no limit) if this is intended",
      what, estimated_faces, format_bytes(estimated_faces * kBytesPerFace), kBytesPerFace, cap));
}

double faces_for_edge_length(double area, double h) { return area / (std::sqrt(3.0) / 4 * h * h); }

double estimate_remesh_faces(const SurfaceMesh& mesh, const RemeshOptions& options) {
  double hmax = options.hmax;
  if (hmax == 0) hmax = resolution_length(mesh);  // remesh()'s default: about as many faces as the input
  if (!(hmax > 0)) return std::numeric_limits<double>::quiet_NaN();
  return faces_for_edge_length(total_area(mesh), hmax);
}

std::size_t find_non_finite(std::span<const double> values) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) return i;
  return std::size_t(-1);
}

std::size_t find_non_finite(std::span<const Vec3> values) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i][0]) || !std::isfinite(values[i][1]) || !std::isfinite(values[i][2])) return i;
  return std::size_t(-1);
}

void require_finite(std::span<const double> values, std::string_view what) {
  if (const std::size_t i = find_non_finite(values); i < values.size())
    throw NumericalError(fmt::format("{}: {} at vertex {} (of {})", what, values[i], i + 1, values.size()));
}

void require_finite(std::span<const Vec3> values, std::string_view what) {
  if (const std::size_t i = find_non_finite(values); i < values.size()) {
    const Vec3& v = values[i];
    throw NumericalError(
        fmt::format("{}: ({}, {}, {}) at vertex {} (of {})", what, v[0], v[1], v[2], i + 1, values.size()));
  }
}

}  // namespace bodyfit
