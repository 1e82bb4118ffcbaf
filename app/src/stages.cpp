// The stages on a mesh in memory (stages.hpp).
#include <bodyfit/app/stages.hpp>

#include <bodyfit/error.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/projection.hpp>

#include <fmt/format.h>

#include <chrono>
#include <cmath>

namespace bodyfit {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string json_number(double x) { return std::isfinite(x) ? fmt::format("{}", x) : "null"; }

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", int(c));
    else out += c;
  }
  return out + "\"";
}

std::string json_vec(const Vec3& v) {
  return fmt::format("[{}, {}, {}]", json_number(v[0]), json_number(v[1]), json_number(v[2]));
}

}  // namespace

ScalarField distance_stage(SurfaceMesh& mesh, const ScalarField* phi, int region, const DistanceOptions& options,
                           DistanceReport* report) {
  ScalarField d;
  if (phi) {
    d = signed_distance(mesh, *phi, options, report);
  } else {
    // The region is the faces whose ref is the given one; its interface, the edges between it and
    // the other faces (whatever the file marked as interface).
    for (auto f : mesh.faces()) mesh.region(f) = mesh.region(f) == region ? kInside : kOutside;
    update_interface_from_regions(mesh);
    d = signed_distance_to_region(mesh, options, report);
  }
  // Medit files cannot hold infinities portably: ±1e300 instead.
  for (double& value : d)
    if (std::isinf(value)) value = value > 0 ? 1e300 : -1e300;
  require_finite(d, "distance: the signed distance");
  return d;
}

ScalarField advect_stage(const SurfaceMesh& mesh, const ScalarField& phi, const VectorField& velocity, double time,
                         const AdvectionOptions& options, AdvectionReport* report) {
  AdvectionReport local;
  AdvectionReport& r = report ? *report : local;
  ScalarField result = advect(mesh, phi, velocity, time, options, &r);
  if (r.lost > 0)
    throw NumericalError(fmt::format(
        "advect: {} of {} characteristics were lost (a walk stalled or overflowed, or a trace reached its bound of "
        "sub-steps): shorten the time or check the velocity",
        r.lost, r.traced));
  require_finite(result, "advect: the advected level set");
  return result;
}

DiscretizeStageReport discretize_stage(SurfaceMesh& mesh, const ScalarField& phi, const DiscretizeOptions& cut,
                                       RemeshOptions options, bool remesh_after) {
  if (remesh_after) check_face_budget(estimate_remesh_faces(mesh, options), "discretize: edges of at most hmax");
  // The default size is the input's resolution, measured before the cut adds its small edges.
  if (options.hmax <= 0) options.hmax = resolution_length(mesh);
  // S is the input: the cut puts points on its triangles, it makes no new surface (and the slivers
  // it leaves would make the remesh's curvature bound, ReferenceSurface::max_curvature, meaningless).
  if (remesh_after && !options.reference) options.reference = std::make_shared<const ReferenceSurface>(mesh);
  DiscretizeStageReport report;
  auto start = std::chrono::steady_clock::now();
  report.cut = discretize(mesh, phi, cut);
  report.cut_ms = ms_since(start);
  if (remesh_after) {
    start = std::chrono::steady_clock::now();
    report.remesh = remesh(mesh, options);
    report.remesh_ms = ms_since(start);
  }
  return report;
}

RemeshReport remesh_stage(SurfaceMesh& mesh, const RemeshOptions& options) {
  check_face_budget(estimate_remesh_faces(mesh, options), "remesh: edges of at most hmax");
  return remesh(mesh, options);
}

MeshInfo describe_mesh(const SurfaceMesh& mesh) {
  MeshInfo info;
  info.vertices = mesh.n_vertices();
  info.edges = mesh.n_edges();
  info.faces = mesh.n_faces();
  info.box = bounding_box(mesh);
  info.quality = quality_stats(mesh);
  info.edge_lengths = edge_length_stats(mesh);
  info.area = total_area(mesh);
  for (auto f : mesh.faces()) {
    auto& r = info.regions[mesh.region(f)];
    ++r.faces;
    r.area += face_area(mesh, f);
  }
  for (auto e : mesh.edges()) {
    info.interface_edges += mesh.interface(e);
    info.ridges += mesh.ridge(e);
    info.required_edges += mesh.required(e);
  }
  for (auto v : mesh.vertices()) {
    info.corners += mesh.corner(v);
    info.required_vertices += mesh.required(v);
  }
  info.interface_length = interface_length(mesh);
  info.curves = interface_curves(mesh);
  info.components = connected_components(mesh);
  for (const auto& loop : boundary_loops(mesh)) {
    double length = 0;
    for (std::size_t i = 0; i < loop.size(); ++i)
      length += (mesh.point(loop[(i + 1) % loop.size()]) - mesh.point(loop[i])).norm();
    info.loop_lengths.push_back(length);
  }
  info.euler = euler_characteristic(mesh);
  return info;
}

std::string to_json(const MeshInfo& m, const std::string& file) {
  std::string regions, loops;
  for (const auto& [ref, r] : m.regions)
    regions += fmt::format("{}{{\"ref\": {}, \"faces\": {}, \"area\": {}}}", regions.empty() ? "" : ", ", ref, r.faces,
                           json_number(r.area));
  for (double l : m.loop_lengths) loops += fmt::format("{}{}", loops.empty() ? "" : ", ", json_number(l));
  std::string s = "{\n";
  s += fmt::format("  \"file\": {},\n", json_string(file));
  s += fmt::format("  \"vertices\": {}, \"edges\": {}, \"faces\": {},\n", m.vertices, m.edges, m.faces);
  s += fmt::format("  \"bounding_box\": {{\"min\": {}, \"max\": {}, \"diagonal\": {}}},\n", json_vec(m.box.min),
                   json_vec(m.box.max), json_number(m.box.diagonal()));
  s += fmt::format("  \"area\": {},\n", json_number(m.area));
  s += fmt::format("  \"quality\": {{\"min\": {}, \"mean\": {}, \"max\": {}, \"share_below_0_3\": {}}},\n",
                   json_number(m.quality.min), json_number(m.quality.mean), json_number(m.quality.max),
                   json_number(m.quality.share_below_0_3));
  s += fmt::format("  \"edge_length\": {{\"min\": {}, \"mean\": {}, \"max\": {}, \"stddev\": {}}},\n",
                   json_number(m.edge_lengths.min), json_number(m.edge_lengths.mean), json_number(m.edge_lengths.max),
                   json_number(m.edge_lengths.stddev));
  s += fmt::format("  \"regions\": [{}],\n", regions);
  s += fmt::format("  \"interface\": {{\"edges\": {}, \"length\": {}, \"closed_curves\": {}, \"open_curves\": {}}},\n",
                   m.interface_edges, json_number(m.interface_length), m.curves.closed, m.curves.open);
  s += fmt::format("  \"components\": {},\n", m.components);
  s += fmt::format("  \"boundary_loops\": {{\"count\": {}, \"lengths\": [{}]}},\n", m.loop_lengths.size(), loops);
  s += fmt::format("  \"euler_characteristic\": {},\n", m.euler);
  s += fmt::format("  \"ridges\": {}, \"corners\": {}, \"required_vertices\": {}, \"required_edges\": {}\n", m.ridges,
                   m.corners, m.required_vertices, m.required_edges);
  return s + "}\n";
}

std::string to_text(const MeshInfo& m, const std::string& file) {
  auto line = [](const char* label, const std::string& value) { return fmt::format("  {:<17} {}\n", label, value); };
  std::string s = fmt::format("{}\n", file);
  s += line("size", fmt::format("{} vertices, {} edges, {} faces", m.vertices, m.edges, m.faces));
  s += line("bounding box", fmt::format("[{:.6g}, {:.6g}] × [{:.6g}, {:.6g}] × [{:.6g}, {:.6g}], diagonal {:.6g}",
                                        m.box.min[0], m.box.max[0], m.box.min[1], m.box.max[1], m.box.min[2],
                                        m.box.max[2], m.box.diagonal()));
  s += line("area", fmt::format("{:.6g}", m.area));
  s += line("quality", fmt::format("min {:.3f}, mean {:.3f}, {:.2f} % below 0.3", m.quality.min, m.quality.mean,
                                   100 * m.quality.share_below_0_3));
  s += line("edge length", fmt::format("min {:.4g}, mean {:.4g}, max {:.4g}, stddev {:.3g}", m.edge_lengths.min,
                                       m.edge_lengths.mean, m.edge_lengths.max, m.edge_lengths.stddev));
  for (const auto& [ref, r] : m.regions) {
    std::string label = fmt::format("region {}", ref);
    s += line(label.c_str(), fmt::format("{} faces, area {:.6g}{}", r.faces, r.area,
                                         ref == kInside ? " (inside G)"
                                         : ref == kOutside ? " (outside G)"
                                                                    : ""));
  }
  s += line("interface", fmt::format("{} edges, length {:.6g}, {} closed and {} open curve(s)", m.interface_edges,
                                     m.interface_length, m.curves.closed, m.curves.open));
  std::string loops;
  for (std::size_t i = 0; i < m.loop_lengths.size() && i < 8; ++i) loops += fmt::format("{}{:.6g}", i ? ", " : "", m.loop_lengths[i]);
  if (m.loop_lengths.size() > 8) loops += ", …";
  s += line("topology", fmt::format("{} component(s), Euler characteristic {}, {} boundary loop(s){}", m.components,
                                    m.euler, m.loop_lengths.size(), loops.empty() ? "" : " of length " + loops));
  s += line("features", fmt::format("{} ridge(s), {} corner(s), {} required vertices, {} required edges", m.ridges,
                                    m.corners, m.required_vertices, m.required_edges));
  return s;
}

}  // namespace bodyfit
