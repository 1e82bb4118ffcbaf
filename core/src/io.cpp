// TEMPORARY minimal implementation (ASCII Medit only, no validation); the io helper replaces it.
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/io.hpp>

#include <fstream>
#include <sstream>

namespace bodyfit {

SurfaceMesh read_mesh(const std::filesystem::path& file, const ReadOptions&) {
  std::ifstream in(file);
  if (!in) throw file_error(file, "cannot open");
  SurfaceMesh mesh;
  std::string word;
  std::vector<VertexHandle> vs;
  while (in >> word) {
    if (word == "Vertices") {
      std::size_t n;
      in >> n;
      for (std::size_t i = 0; i < n; ++i) {
        double x, y, z;
        int ref;
        in >> x >> y >> z >> ref;
        vs.push_back(mesh.add_vertex(Vec3(x, y, z)));
      }
    } else if (word == "Triangles") {
      std::size_t n;
      in >> n;
      for (std::size_t i = 0; i < n; ++i) {
        int a, b, c, ref;
        in >> a >> b >> c >> ref;
        auto f = mesh.add_face(vs[a - 1], vs[b - 1], vs[c - 1]);
        mesh.region(f) = ref;
      }
    }
  }
  update_interface_from_regions(mesh);
  return mesh;
}

void write_mesh(const SurfaceMesh& mesh, const std::filesystem::path& file) {
  write_atomically(file, [&](std::ostream& out) {
    out.precision(17);
    out << "MeshVersionFormatted 2\nDimension 3\nVertices\n" << mesh.n_vertices() << "\n";
    for (auto v : mesh.vertices()) out << mesh.point(v)[0] << ' ' << mesh.point(v)[1] << ' ' << mesh.point(v)[2] << " 0\n";
    out << "Triangles\n" << mesh.n_faces() << "\n";
    for (auto f : mesh.faces()) {
      for (auto v : mesh.fv_range(f)) out << v.idx() + 1 << ' ';
      out << mesh.region(f) << "\n";
    }
    out << "End\n";
  });
}

void write_scalar_sol(const std::filesystem::path& file, const ScalarField& values) {
  write_atomically(file, [&](std::ostream& out) {
    out.precision(17);
    out << "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n" << values.size() << "\n1 1\n";
    for (double v : values) out << v << "\n";
    out << "End\n";
  });
}

ScalarField read_scalar_sol(const std::filesystem::path& file, std::size_t expected) {
  std::ifstream in(file);
  if (!in) throw file_error(file, "cannot open");
  std::string word;
  while (in >> word && word != "SolAtVertices") {}
  std::size_t n;
  int a, b;
  in >> n >> a >> b;
  if (expected && n != expected) throw file_error(file, "size mismatch");
  ScalarField values(n);
  for (auto& v : values) in >> v;
  return values;
}

}  // namespace bodyfit
