// bodyfit info FILE [--json]: what a mesh is made of (counts, size, quality, edge lengths, regions,
// interface, topology, feature tags), as one screen of aligned text or as JSON for scripts.
#include "commands.hpp"

#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

struct RegionInfo {
  std::size_t faces = 0;
  double area = 0;
};

struct MeshInfo {
  std::string file;
  std::size_t vertices = 0, edges = 0, faces = 0;
  bodyfit::BoundingBox box;
  bodyfit::QualityStats quality;
  bodyfit::EdgeLengthStats edge_lengths;
  double area = 0;
  std::map<int, RegionInfo> regions;
  std::size_t interface_edges = 0;
  double interface_length = 0;
  bodyfit::InterfaceCurves curves;
  int components = 0;
  std::vector<double> loop_lengths;
  long euler = 0;
  std::size_t ridges = 0, corners = 0, required_vertices = 0, required_edges = 0;
};

MeshInfo gather(const bodyfit::SurfaceMesh& mesh, const std::string& file) {
  MeshInfo info;
  info.file = file;
  info.vertices = mesh.n_vertices();
  info.edges = mesh.n_edges();
  info.faces = mesh.n_faces();
  info.box = bodyfit::bounding_box(mesh);
  info.quality = bodyfit::quality_stats(mesh);
  info.edge_lengths = bodyfit::edge_length_stats(mesh);
  info.area = bodyfit::total_area(mesh);
  for (auto f : mesh.faces()) {
    auto& r = info.regions[mesh.region(f)];
    ++r.faces;
    r.area += bodyfit::face_area(mesh, f);
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
  info.interface_length = bodyfit::interface_length(mesh);
  info.curves = bodyfit::interface_curves(mesh);
  info.components = bodyfit::connected_components(mesh);
  for (const auto& loop : bodyfit::boundary_loops(mesh)) {
    double length = 0;
    for (std::size_t i = 0; i < loop.size(); ++i)
      length += (mesh.point(loop[(i + 1) % loop.size()]) - mesh.point(loop[i])).norm();
    info.loop_lengths.push_back(length);
  }
  info.euler = bodyfit::euler_characteristic(mesh);
  return info;
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

std::string json_vec(const bodyfit::Vec3& v) {
  return fmt::format("[{}, {}, {}]", json_number(v[0]), json_number(v[1]), json_number(v[2]));
}

std::string to_json(const MeshInfo& m) {
  std::string regions, loops;
  for (const auto& [ref, r] : m.regions)
    regions += fmt::format("{}{{\"ref\": {}, \"faces\": {}, \"area\": {}}}", regions.empty() ? "" : ", ", ref, r.faces,
                           json_number(r.area));
  for (double l : m.loop_lengths) loops += fmt::format("{}{}", loops.empty() ? "" : ", ", json_number(l));
  std::string s = "{\n";
  s += fmt::format("  \"file\": {},\n", json_string(m.file));
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

std::string to_text(const MeshInfo& m) {
  auto line = [](const char* label, const std::string& value) { return fmt::format("  {:<17} {}\n", label, value); };
  std::string s = fmt::format("{}\n", m.file);
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
                                         ref == bodyfit::kInside ? " (inside G)"
                                         : ref == bodyfit::kOutside ? " (outside G)"
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

bodyfit::cli::Command setup_info(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "describe a mesh: counts, size, quality, edge lengths, regions, interface, "
                                         "topology (components, boundary loops, Euler characteristic), feature tags");
  auto file = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("file", *file, "mesh file (.mesh, .meshb, .obj, .off, .ply, .stl)")->required();
  cmd->add_flag("--json", *json, "print JSON (for scripts) instead of text");
  return {cmd, [=]() {
            auto mesh = bodyfit::read_mesh(*file);
            auto info = gather(mesh, *file);
            std::fputs((*json ? to_json(info) : to_text(info)).c_str(), stdout);
            return 0;
          }};
}

BODYFIT_COMMAND(20, setup_info);

}  // namespace
