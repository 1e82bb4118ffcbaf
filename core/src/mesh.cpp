#include <bodyfit/mesh.hpp>

namespace bodyfit {

SurfaceMesh::SurfaceMesh() {
  request_vertex_status();
  request_edge_status();
  request_face_status();
  add_property(region_, "f:region");
  add_property(edge_ref_, "e:ref");
  add_property(interface_, "e:interface");
  add_property(ridge_, "e:ridge");
  add_property(required_edge_, "e:required");
  add_property(vertex_ref_, "v:ref");
  add_property(corner_, "v:corner");
  add_property(required_vertex_, "v:required");
  add_property(phi_, "v:phi");
}

ScalarField SurfaceMesh::phi_field() const {
  ScalarField values(n_vertices());
  for (auto v : vertices()) values[v.idx()] = phi(v);
  return values;
}

void SurfaceMesh::set_phi(const ScalarField& values) {
  for (auto v : vertices()) phi(v) = values.at(v.idx());
}

bool SurfaceMesh::has_regions() const {
  for (auto f : faces())
    if (inside(f)) return true;
  return false;
}

void update_interface_from_regions(SurfaceMesh& mesh) {
  for (auto e : mesh.edges()) {
    bool is_interface = false;
    if (!mesh.is_boundary(e)) {
      auto f0 = mesh.face_handle(mesh.halfedge_handle(e, 0));
      auto f1 = mesh.face_handle(mesh.halfedge_handle(e, 1));
      is_interface = mesh.inside(f0) != mesh.inside(f1);
    }
    mesh.interface(e) = is_interface;
    if (is_interface) mesh.edge_ref(e) = kInterfaceRef;
    else if (mesh.edge_ref(e) == kInterfaceRef) mesh.edge_ref(e) = 0;
  }
}

void label_regions_from_phi(SurfaceMesh& mesh) {
  for (auto f : mesh.faces()) {
    double sum = 0;
    for (auto v : mesh.fv_range(f)) sum += mesh.phi(v);
    mesh.region(f) = sum < 0 ? kInside : kOutside;
  }
  update_interface_from_regions(mesh);
}

}  // namespace bodyfit
