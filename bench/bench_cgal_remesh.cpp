// CGAL's isotropic remeshing on the input bodyfit's remesher gets, for the side-by-side figures of
// docs/validation/remeshing.md (built only when CMake finds CGAL; never linked into the core).
//
//   bench_cgal_remesh input target [--iterations 3] [--csv file]
//
// Reads the input with bodyfit's readers (Medit/OFF/OBJ/PLY/STL), runs
// CGAL::Polygon_mesh_processing::isotropic_remeshing with `iterations` iterations (3 by default)
// at the target edge length on a CGAL::Surface_mesh (its default: projection onto the input
// triangles), and prints the time of that call alone, the faces, the minimum and mean quality
// q = 4√3·area/Σl² (bodyfit's triangle_quality: 1 equilateral) and the longest edge / target. CSV
// columns: tool,input_faces,target,iterations,ms,faces,q_min,q_mean,share_below_0_3,max_edge_ratio,cpu_ms
// (the first columns of bench_remesh_sizes', so both can append to one file).
#include "bench_args.hpp"

#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

bodyfit::Vec3 to_vec(const Kernel::Point_3& p) { return bodyfit::Vec3(p.x(), p.y(), p.z()); }

}  // namespace

int main(int argc, char** argv) {
  std::string input, csv;
  double target = 0;
  unsigned iterations = 3;
  bench::Arguments args("bench_cgal_remesh",
                        "usage: bench_cgal_remesh input target [--iterations 3] [--csv out.csv]\n"
                        "  CGAL::Polygon_mesh_processing::isotropic_remeshing of the input (Medit/OFF/OBJ/PLY/STL) at\n"
                        "  the target edge length; prints time, faces, quality and longest edge / target, and appends\n"
                        "  a row to out.csv.\n");
  args.positional("input", input);
  args.positional("target", target);
  args.option("--iterations", iterations);
  args.option("--csv", csv);
  args.parse(argc, argv);
  if (input.empty() || !(target > 0)) args.fail("give an input mesh and a target length > 0");
  const bodyfit::SurfaceMesh source = bodyfit::read_mesh(input);
  Mesh mesh;
  std::vector<Mesh::Vertex_index> index;
  index.reserve(source.n_vertices());
  for (auto v : source.vertices()) {
    const auto& p = source.point(v);
    index.push_back(mesh.add_vertex(Kernel::Point_3(p[0], p[1], p[2])));
  }
  for (auto f : source.faces()) {
    auto vs = bodyfit::face_vertices(source, f);
    mesh.add_face(index[vs[0].idx()], index[vs[1].idx()], index[vs[2].idx()]);
  }
  const std::size_t input_faces = mesh.number_of_faces();

  const double cpu0 = process_cpu_ms();
  const auto start = std::chrono::steady_clock::now();
  CGAL::Polygon_mesh_processing::isotropic_remeshing(faces(mesh), target, mesh,
                                                     CGAL::parameters::number_of_iterations(iterations));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const double cpu_ms = process_cpu_ms() - cpu0;
  mesh.collect_garbage();

  double q_min = 1, q_sum = 0, longest = 0;
  std::size_t below = 0;
  for (auto f : mesh.faces()) {
    std::array<bodyfit::Vec3, 3> p;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) p[std::size_t(k++)] = to_vec(mesh.point(v));
    const double q = bodyfit::triangle_quality(p[0], p[1], p[2]);
    q_min = std::min(q_min, q);
    q_sum += q;
    below += q < 0.3;
  }
  for (auto e : mesh.edges())
    longest = std::max(longest, (to_vec(mesh.point(mesh.vertex(e, 0))) - to_vec(mesh.point(mesh.vertex(e, 1)))).norm());
  const std::size_t faces = mesh.number_of_faces();
  const double q_mean = faces ? q_sum / double(faces) : 0.0;
  std::printf("cgal    in %7zu target %.5g iterations %u | %9.1f ms (cpu %.1f) | faces %7zu | q min %.3f mean %.4f <0.3 %.2e | "
              "max edge / target %.3f\n",
              input_faces, target, iterations, ms, cpu_ms, faces, q_min, q_mean, faces ? double(below) / double(faces) : 0.0,
              longest / target);
  if (!csv.empty()) {
    const bool fresh = !std::ifstream(csv).good();
    std::ofstream out(csv, std::ios::app);
    if (fresh) out << "tool,input_faces,target,iterations,ms,faces,q_min,q_mean,share_below_0_3,max_edge_ratio,cpu_ms\n";
    out << "cgal," << input_faces << ',' << target << ',' << iterations << ',' << ms << ',' << faces << ',' << q_min
        << ',' << q_mean << ',' << (faces ? double(below) / double(faces) : 0.0) << ',' << longest / target << ','
        << cpu_ms << '\n';
  }
  return 0;
}
