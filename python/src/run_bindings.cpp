// The module's runs: bodyfit.run's native part — a case from a file or a dict, the model from a
// Python object, a case's `python` model or a plugin, signals as the command line takes them
// (<bodyfit/app/run_case.hpp> does the run) (bindings.hpp).
#include "arrays.hpp"
#include "bindings.hpp"
#include "python_model.hpp"

#include <bodyfit/app/run_case.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <optional>
#include <sstream>

namespace bodyfit::python {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void on_run_signal(int) {
  if (g_interrupted.exchange(true)) std::_Exit(130);
}

/// SIGINT, SIGTERM and SIGHUP end the run after the iteration in progress (checkpointed), as on
/// the command line; Python's handlers are back when the run returns.
class RunSignals {
 public:
  RunSignals() {
    g_interrupted = false;
    for (int s : kSignals) previous_.push_back(std::signal(s, on_run_signal));
  }
  ~RunSignals() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) std::signal(kSignals[i], previous_[i]);
  }

 private:
  static constexpr std::array<int, 3> kSignals{SIGINT, SIGTERM, SIGHUP};
  std::vector<void (*)(int)> previous_;
};

/// A Python value as TOML (a case given as a dict).
std::unique_ptr<toml::node> toml_of(py::handle value, const std::string& key);

toml::table toml_table(py::handle dict, const std::string& where) {
  if (!py::isinstance<py::dict>(dict))
    throw InputError(fmt::format("{}: a dict expected, got a {}", where, std::string(py::str(dict.get_type().attr("__name__")))));
  toml::table table;
  for (auto [key, value] : py::reinterpret_borrow<py::dict>(dict)) {
    const std::string k = py::str(key);
    table.insert(k, *toml_of(value, where.empty() ? k : where + "." + k));
  }
  return table;
}

std::unique_ptr<toml::node> toml_of(py::handle value, const std::string& key) {
  if (py::isinstance<py::bool_>(value)) return std::make_unique<toml::value<bool>>(value.cast<bool>());
  if (py::isinstance<py::int_>(value)) return std::make_unique<toml::value<std::int64_t>>(value.cast<std::int64_t>());
  if (py::isinstance<py::float_>(value)) return std::make_unique<toml::value<double>>(value.cast<double>());
  if (py::isinstance<py::str>(value)) return std::make_unique<toml::value<std::string>>(value.cast<std::string>());
  if (py::hasattr(value, "__fspath__"))
    return std::make_unique<toml::value<std::string>>(py::str(py::module_::import("os").attr("fspath")(value)).cast<std::string>());
  if (py::isinstance<py::dict>(value)) return std::make_unique<toml::table>(toml_table(value, key));
  if (py::isinstance<py::array>(value) && py::reinterpret_borrow<py::array>(value).ndim() == 0)
    return toml_of(value.attr("item")(), key);
  if (py::isinstance<py::sequence>(value) || py::isinstance<py::array>(value)) {
    auto array = std::make_unique<toml::array>();
    for (py::handle item : value) array->push_back(*toml_of(item, key));
    return array;
  }
  throw InputError(fmt::format("{}: a {} cannot go into a case (numbers, strings, booleans, lists and dicts can)", key,
                               std::string(py::str(value.get_type().attr("__name__")))));
}

/// The model of a run: the Python object given, a case's `python` model (imported by this
/// interpreter, not through the plugin: the process has its interpreter already), or the plugin
/// the case names.
ModelLoader python_loader(py::object model) {
  return [model](const CaseConfig& config) -> LoadedModel {
    std::unique_ptr<PythonModel> python;
    std::string origin;
    if (model) {
      if (config.model != "python")
        throw InputError(fmt::format("[model] name = \"{}\" and a model object given to run(): leave name out (or "
                                     "\"python\") to run the object",
                                     config.model));
      py::gil_scoped_acquire gil;
      origin = fmt::format("python object {}", std::string(py::str(model.get_type().attr("__name__"))));
      python = std::make_unique<PythonModel>(model, origin);
    } else if (config.model == "python") {
      python = PythonModel::from_case();
      origin = "python";
    } else {
      return load_case_model(config);
    }
    LoadedModel loaded = LoadedModel::hosted(std::move(python), origin);
    configure_model(loaded, config.model_parameters, case_surface_source(config));
    return loaded;
  };
}

py::dict run(py::object case_, std::optional<std::filesystem::path> out, py::object set, py::object model,
             bool progress, bool resume, bool overwrite, bool force, bool verbose) {
  RunRequest request;
  if (py::isinstance<py::dict>(case_)) {
    toml::table table = toml_table(case_, "");
    if (!model.is_none()) {
      // The object is the model: [model] holds its parameters (and no name, or "python").
      auto* m = table["model"].as_table();
      if (!m) table.insert("model", toml::table{{"name", "python"}});
      else if (!m->contains("name")) m->insert("name", "python");
    }
    request.case_table = std::move(table);
    request.case_dir = std::filesystem::current_path();
  } else {
    request.case_file = py::str(py::module_::import("os").attr("fspath")(case_)).cast<std::string>();
    if (!model.is_none()) {
      // As for a dict: [model] may leave the name out when an object is the model.
      toml::table table = read_case_table(request.case_file);
      if (auto* m = table["model"].as_table(); m && !m->contains("name")) m->insert("name", "python");
      request.case_table = std::move(table);
      request.case_dir = request.case_file.parent_path();
    }
  }
  if (!set.is_none()) {
    if (!py::isinstance<py::dict>(set))
      throw InputError(fmt::format("run(): set: a dict {{\"dotted.key\": value}} expected, got a {}",
                                   std::string(py::str(set.get_type().attr("__name__")))));
    for (auto [key, value] : py::reinterpret_borrow<py::dict>(set)) {
      toml::table one;
      one.insert("v", *toml_of(value, py::str(key)));
      std::ostringstream text;
      one.get("v")->visit([&](const auto& node) { text << node; });
      request.sets.push_back(fmt::format("{}={}", std::string(py::str(key)), text.str()));
    }
  }
  if (out) request.output_dir = *out;
  request.progress = progress;
  request.resume = resume;
  request.overwrite = overwrite;
  request.force = force;
  request.verbose = verbose;
  request.interrupted = &g_interrupted;
  request.load_model = python_loader(model.is_none() ? py::object() : model);
  RunOutcome outcome;
  {
    RunSignals signals;
    py::gil_scoped_release release;
    outcome = run_case(request);
  }
  py::dict result;
  result["output_dir"] = outcome.output_dir.string();
  result["exit_code"] = outcome.exit_code;
  result["iteration"] = outcome.result.iteration;
  result["time"] = outcome.result.time;
  result["reason"] = std::string(to_string(outcome.result.reason));
  result["message"] = outcome.result.message;
  return result;
}

}  // namespace

void bind_runs(py::module_& m) {
  m.def("_run", &run, py::arg("case"), py::arg("out"), py::arg("set"), py::arg("model"), py::arg("progress"),
        py::arg("resume"), py::arg("overwrite"), py::arg("force"), py::arg("verbose"));
}

}  // namespace bodyfit::python
