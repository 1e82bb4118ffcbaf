#pragma once
// The parts of the bodyfit module (_bodyfit), each binding one concept into it: meshes, fields and
// generators (mesh_bindings.cpp), the stages (stage_bindings.cpp), runs (run_bindings.cpp); the
// model types are python_model.hpp's. module.cpp puts them together.
#include <pybind11/pybind11.h>

namespace bodyfit::python {

void bind_meshes(pybind11::module_& m);
void bind_stages(pybind11::module_& m);
void bind_runs(pybind11::module_& m);

}  // namespace bodyfit::python
