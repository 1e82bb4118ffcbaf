#pragma once
// The Mesh of the Python module: the engine's mesh, shared (the numpy views of its arrays keep it
// alive), with named vertex fields. Stages never change a Mesh: they return a new one.
#include <bodyfit/mesh.hpp>

#include <pybind11/pybind11.h>

#include <memory>

namespace bodyfit::python {

struct Mesh {
  std::shared_ptr<SurfaceMesh> mesh;
  pybind11::dict fields;
  std::size_t n_vertices() const { return mesh->n_vertices(); }
};

inline Mesh wrap(SurfaceMesh&& mesh) { return Mesh{std::make_shared<SurfaceMesh>(std::move(mesh)), pybind11::dict()}; }

}  // namespace bodyfit::python
