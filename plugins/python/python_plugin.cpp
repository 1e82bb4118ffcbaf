// The `python` model plugin: `[model] name = "python"`, `module = "my_model.py"`, `class =
// "MyModel"`, the other keys the class's parameters. The plugin starts an interpreter in the
// process (the first time one is needed) and hands the class to PythonModel
// (python/src/python_model.hpp), which bodyfit.run uses too.
#include "python_model.hpp"

#include <pybind11/embed.h>

#include <dlfcn.h>

#include <filesystem>

namespace {

namespace py = pybind11;

// The types a model's methods receive, bound in the embedded interpreter.
PYBIND11_EMBEDDED_MODULE(_bodyfit_host, m) { bodyfit::python::bind_model_types(m); }

/// Keep a shared object loaded for the life of the process: the interpreter outlives the model.
void pin(const void* symbol, int extra_flags) {
  Dl_info info{};
  if (dladdr(symbol, &info) && info.dli_fname) dlopen(info.dli_fname, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE | extra_flags);
}

/// The interpreter, started once. libpython is made global first: the extension modules a model
/// imports (numpy's) take Python's symbols from the process, not from this plugin. The GIL is
/// released afterwards; every call into the model takes it (PythonModel).
void start_interpreter() {
  if (Py_IsInitialized()) return;
  pin(reinterpret_cast<const void*>(&Py_IsInitialized), RTLD_GLOBAL);
  pin(reinterpret_cast<const void*>(&start_interpreter), 0);
  // No signal handlers of Python's: Ctrl-C is the driver's (the run stops after the iteration).
  py::initialize_interpreter(false);
  py::module_::import("_bodyfit_host");
  // A model's `import bodyfit` finds the package of this build or install, wherever the Python
  // path points: <build>/python beside lib/, or <prefix>/lib/python3.X/dist-packages.
  Dl_info self{};
  if (dladdr(reinterpret_cast<const void*>(&start_interpreter), &self) && self.dli_fname) {
    const auto plugins = std::filesystem::path(self.dli_fname).parent_path();
    const std::string version = "python" + std::to_string(PY_MAJOR_VERSION) + "." + std::to_string(PY_MINOR_VERSION);
    for (const auto& package : {plugins / "../../../python", plugins / "../.." / version / "dist-packages"})
      if (std::filesystem::exists(package / "bodyfit" / "__init__.py")) {
        py::module_::import("sys").attr("path").attr("append")(std::filesystem::weakly_canonical(package).string());
        break;
      }
  }
  PyEval_SaveThread();
}

}  // namespace

BODYFIT_PLUGIN_EXPORT std::uint32_t bodyfit_plugin_abi() { return bodyfit::kPluginAbi; }
BODYFIT_PLUGIN_EXPORT bodyfit::VelocityModel* bodyfit_create() {
  start_interpreter();
  return bodyfit::python::PythonModel::from_case().release();
}
BODYFIT_PLUGIN_EXPORT void bodyfit_destroy(bodyfit::VelocityModel* model) { delete model; }
