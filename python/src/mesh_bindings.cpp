// The module's meshes: Mesh from and to numpy arrays, files of every format, .sol fields, the
// generators (bindings.hpp).
#include "arrays.hpp"
#include "bindings.hpp"
#include "py_mesh.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/io.hpp>

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <climits>
#include <cmath>
#include <optional>

namespace bodyfit::python {
namespace {

VtuFields vtu_fields(const Mesh& m) {
  VtuFields out;
  for (auto [key, value] : m.fields) {
    const std::string name = py::str(key);
    if (py::isinstance<py::array>(value) && py::reinterpret_borrow<py::array>(value).ndim() == 2)
      out.point_vectors.emplace_back(name, vector_field(value, "field " + name, m.n_vertices()));
    else
      out.point_scalars.emplace_back(name, scalar_field(value, "field " + name, m.n_vertices()));
  }
  return out;
}

}  // namespace

void bind_meshes(py::module_& m) {
  py::class_<Mesh>(m, "Mesh", "A triangulated surface with its regions (G: ref 3, S\\G: ref 2) and vertex fields")
      .def(py::init([](py::handle vertices, py::handle triangles, py::handle regions) {
             const auto xyz = checked_doubles(vertices, "vertices", 0, 3);
             const auto tri = checked_integers(triangles, "triangles", 3);
             std::vector<int> refs;
             if (!regions.is_none()) {
               for (std::int64_t r : checked_integers(regions, "regions", 0)) {
                 require(r >= INT32_MIN && r <= INT32_MAX, fmt::format("regions: {} does not fit in 32 bits", r));
                 refs.push_back(int(r));
               }
             }
             return wrap(mesh_from_arrays(std::span(xyz.data(), std::size_t(xyz.size())), tri, refs, "bodyfit.Mesh"));
           }),
           py::arg("vertices"), py::arg("triangles"), py::arg("regions") = py::none(),
           "A mesh from (n, 3) float64 vertices and (m, 3) integer triangles (0-based), with optional (m,) face "
           "refs; checked as a file is (finite, indices in range, no zero-area triangle, manifold)")
      .def_property_readonly("n_vertices", [](const Mesh& m) { return m.mesh->n_vertices(); })
      .def_property_readonly("n_faces", [](const Mesh& m) { return m.mesh->n_faces(); })
      .def_property_readonly(
          "vertices",
          [](py::object self) {
            auto& m = self.cast<Mesh&>();
            return view(m.n_vertices() ? &m.mesh->point(VertexHandle(0))[0] : nullptr, m.n_vertices(), 3, self, true);
          },
          "(n, 3) vertex positions: a writable view of the mesh's own array")
      .def_property_readonly(
          "triangles",
          [](const Mesh& m) {
            py::array_t<std::int64_t> a({py::ssize_t(m.mesh->n_faces()), py::ssize_t(3)});
            auto* p = a.mutable_data();
            for (auto f : m.mesh->faces())
              for (auto v : m.mesh->fv_range(f)) *p++ = v.idx();
            return a;
          },
          "(m, 3) int64 vertex indices of the faces (a copy)")
      .def_property_readonly(
          "regions",
          [](const Mesh& m) {
            py::array_t<int> a(py::ssize_t(m.mesh->n_faces()));
            auto* p = a.mutable_data();
            for (auto f : m.mesh->faces()) *p++ = m.mesh->region(f);
            return a;
          },
          "(m,) int32 face refs (a copy): 3 inside G, 2 outside after a cut")
      .def_property_readonly(
          "interface_edges",
          [](const Mesh& m) {
            std::vector<std::int64_t> ends;
            for (auto e : m.mesh->edges())
              if (m.mesh->interface(e)) {
                const auto h = m.mesh->halfedge_handle(e, 0);
                ends.push_back(m.mesh->from_vertex_handle(h).idx());
                ends.push_back(m.mesh->to_vertex_handle(h).idx());
              }
            py::array_t<std::int64_t> a({py::ssize_t(ends.size() / 2), py::ssize_t(2)});
            std::copy(ends.begin(), ends.end(), a.mutable_data());
            return a;
          },
          "(k, 2) vertex indices of the interface edges ∂G (a copy)")
      .def_readwrite("fields", &Mesh::fields, "named vertex fields: (n,) or (n, 3) float64 arrays (written to .vtu)")
      .def(
          "write",
          [](const Mesh& m, const std::filesystem::path& path) {
            const VtuFields fields = vtu_fields(m);
            py::gil_scoped_release release;
            if (path.extension() == ".vtu") write_vtu(*m.mesh, path, fields);
            else write_mesh(*m.mesh, path);
          },
          py::arg("path"), "Write as the extension says: .mesh .meshb .obj .off .ply .stl .vtu (.vtu keeps the fields)")
      .def("copy", [](const Mesh& m) { return Mesh{std::make_shared<SurfaceMesh>(*m.mesh), m.fields.attr("copy")()}; })
      .def("__repr__", [](const Mesh& m) {
        return fmt::format("<bodyfit.Mesh: {} vertices, {} faces>", m.mesh->n_vertices(), m.mesh->n_faces());
      });

  m.def(
      "read",
      [](const std::filesystem::path& path) {
        VtuFields fields;
        SurfaceMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = path.extension() == ".vtu" ? read_vtu(path, &fields) : read_mesh(path);
        }
        Mesh m = wrap(std::move(mesh));
        for (auto& [name, f] : fields.point_scalars) m.fields[py::str(name)] = copy_of(f);
        for (auto& [name, f] : fields.point_vectors) m.fields[py::str(name)] = copy_of(f);
        return m;
      },
      py::arg("path"), "Read a mesh: .mesh .meshb .obj .off .ply .stl .vtu (with its vertex fields)");
  m.def(
      "read_field",
      [](const std::filesystem::path& path, std::optional<std::size_t> n_vertices) {
        const SolField f = read_sol(path, n_vertices.value_or(0));
        if (f.dimension == 1) return copy_of(ScalarField(f.values));
        py::array_t<double> a({py::ssize_t(f.size()), py::ssize_t(f.dimension)});
        std::copy(f.values.begin(), f.values.end(), a.mutable_data());
        return py::array(a);
      },
      py::arg("path"), py::arg("n_vertices") = py::none(), "The first field of a .sol/.solb file: (n,) or (n, 3)");
  m.def(
      "write_field",
      [](const std::filesystem::path& path, py::handle values) {
        const bool vector = py::isinstance<py::array>(values) && py::reinterpret_borrow<py::array>(values).ndim() == 2;
        if (vector) write_vector_sol(path, vector_field(values, "values", 0));
        else write_scalar_sol(path, scalar_field(values, "values", 0));
      },
      py::arg("path"), py::arg("values"), "Write (n,) or (n, 3) values at the vertices as a .sol/.solb file");
  m.def(
      "sphere",
      [](std::size_t faces, double radius) {
        require(faces >= 20, fmt::format("faces: {} is below 20", faces));
        require(std::isfinite(radius) && radius > 0, fmt::format("radius: {} is not a finite number > 0", radius));
        check_face_budget(double(faces), "sphere");
        SurfaceMesh mesh;
        {
          py::gil_scoped_release release;  // the Mesh (a Python dict inside) is made with the GIL
          mesh = make_sphere({.faces = faces, .radius = radius});
        }
        return wrap(std::move(mesh));
      },
      py::arg("faces") = SphereOptions{}.faces, py::arg("radius") = SphereOptions{}.radius,
      R"(A geodesic sphere of about `faces` triangles (within ±10 %), vertices exactly on it, as `bodyfit mesh sphere`.)");
  m.def(
      "plane",
      [](double size, double h) {
        require(std::isfinite(size) && size > 0, fmt::format("size: {} is not a finite number > 0", size));
        require(std::isfinite(h) && h > 0, fmt::format("h: {} is not a finite number > 0", h));
        check_face_budget(faces_for_edge_length(size * size, h), "plane");
        SurfaceMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = make_plane({.size = size, .h = h});
        }
        return wrap(std::move(mesh));
      },
      py::arg("size") = PlaneOptions{}.size, py::arg("h") = PlaneOptions{}.h,
      R"(The square [-size/2, size/2]² at z = 0 with near-equilateral triangles of edge ≈ h (an open surface).)");
}

}  // namespace bodyfit::python
