// The bodyfit Python module's native part (_bodyfit): its exceptions, the parts bound by
// bindings.hpp (meshes, stages, runs) and python_model.hpp (a model's Step), threads, messages and
// build information. The GIL is released in every stage and run.
#include "arrays.hpp"
#include "bindings.hpp"
#include "python_model.hpp"

#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/plugin_abi.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <memory>

namespace py = pybind11;
using namespace bodyfit;
using namespace bodyfit::python;

PYBIND11_MODULE(_bodyfit, m) {
  m.doc() = "bodyfit's native core: meshes as numpy arrays, the stages, runs, Python velocity models";
  m.attr("__version__") = config::version;
  spdlog::set_pattern("[%T.%e] %^%l%$ %v");  // as the command line's

  // Exceptions: one per exit code of the command line, under bodyfit.Error.
  static py::exception<std::runtime_error> error(m, "Error");
  static py::handle input = PyErr_NewException("bodyfit.InputError", py::make_tuple(error, py::handle(PyExc_ValueError)).ptr(), nullptr);
  static py::handle plugin = PyErr_NewException("bodyfit.PluginError", error.ptr(), nullptr);
  static py::handle numerical =
      PyErr_NewException("bodyfit.NumericalError", py::make_tuple(error, py::handle(PyExc_ArithmeticError)).ptr(), nullptr);
  static py::handle io = PyErr_NewException("bodyfit.IoError", py::make_tuple(error, py::handle(PyExc_OSError)).ptr(), nullptr);
  m.attr("InputError") = input;
  m.attr("PluginError") = plugin;
  m.attr("NumericalError") = numerical;
  m.attr("IoError") = io;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(input.ptr(), e.what());
    } catch (const PluginError& e) {
      PyErr_SetString(plugin.ptr(), e.what());
    } catch (const NumericalError& e) {
      PyErr_SetString(numerical.ptr(), e.what());
    } catch (const IoError& e) {
      PyErr_SetString(io.ptr(), e.what());
    }
  });

  bind_model_types(m);
  bind_meshes(m);
  bind_stages(m);
  bind_runs(m);
  m.def(
      "set_log_level",
      [](const std::string& level) {
        const auto parsed = spdlog::level::from_str(level);
        require(parsed != spdlog::level::off || level == "off",
                fmt::format("set_log_level: '{}', expected trace, debug, info, warning, error, critical or off", level));
        spdlog::set_level(parsed);
      },
      py::arg("level"), "The engine's messages shown: 'info' (the default), 'warning', 'error', 'off', ...");
  m.def(
      "set_threads",
      [](int n) {
        static std::unique_ptr<tbb::global_control> limit;
        require(n >= 0, fmt::format("set_threads: {} is negative (0: every core)", n));
        limit.reset();
        if (n > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, n);
      },
      py::arg("n"), "Worker threads of the parallel stages (0: every core); results do not depend on it");
  m.def("plugin_search_path", [] { return plugin_search_path(); });
  m.def("_build_info", [] {
    py::dict d;
    d["version"] = config::version;
    d["build_type"] = BODYFIT_BUILD_TYPE;
    d["compiler"] = fmt::format("{} {}", BODYFIT_COMPILER_ID, BODYFIT_COMPILER_VERSION);
    d["pybind11"] = fmt::format("{}.{}.{}", PYBIND11_VERSION_MAJOR, PYBIND11_VERSION_MINOR, PYBIND11_VERSION_PATCH);
    d["plugin_abi"] = fmt::format("{}.{}", kPluginAbi >> 16, kPluginAbi & 0xffffu);
    d["cores"] = tbb::info::default_concurrency();
    return d;
  });
}
