#include "python_model.hpp"

#include "arrays.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <pybind11/stl.h>

#include <cmath>

namespace bodyfit::python {
namespace {

/// What a model's method receives: the engine's state of the call, as numpy views.
struct Step {
  const StepContext* context = nullptr;
  std::vector<int> triangles, regions;  ///< built on first use (OpenMesh keeps no index array)

  const StepContext& get() const {
    if (!context)
      throw std::runtime_error("this Step is no longer valid: a Step and its arrays are valid during the call that "
                               "received them (copy what you keep: numpy.array(step.distance))");
    return *context;
  }
  const SurfaceMesh& mesh() const { return get().mesh(); }
  void build_faces() {
    if (!triangles.empty() || mesh().n_faces() == 0) return;
    triangles.reserve(3 * mesh().n_faces());
    regions.reserve(mesh().n_faces());
    for (auto f : mesh().faces()) {
      for (auto v : mesh().fv_range(f)) triangles.push_back(v.idx());
      regions.push_back(mesh().region(f));
    }
  }
};

/// Invalidates a Step when the call that made it returns, whatever the model kept.
class StepScope {
 public:
  explicit StepScope(const StepContext& context) : object_(py::cast(Step{&context, {}, {}})) {}
  ~StepScope() { object_.cast<Step&>().context = nullptr; }
  py::object& object() { return object_; }

 private:
  py::object object_;
};

py::object sparse_matrix(const Eigen::SparseMatrix<double>& m, py::handle owner) {
  py::module_ sparse;
  try {
    sparse = py::module_::import("scipy.sparse");
  } catch (py::error_already_set&) {
    throw py::import_error("the mass and stiffness matrices are scipy.sparse matrices: install SciPy "
                           "(Debian: python3-scipy)");
  }
  if (!m.isCompressed()) throw std::logic_error("sparse matrix not compressed");
  const auto n = std::size_t(m.nonZeros());
  py::array data = view(m.valuePtr(), n, 0, owner);
  py::array indices = view(m.innerIndexPtr(), n, 0, owner);
  py::array indptr = view(m.outerIndexPtr(), std::size_t(m.outerSize()) + 1, 0, owner);
  return sparse.attr("csc_matrix")(py::make_tuple(data, indices, indptr), py::arg("shape") = py::make_tuple(m.rows(), m.cols()),
                                   py::arg("copy") = false);
}

std::string type_name(py::handle value) { return py::str(value.get_type().attr("__name__")); }

/// A Python default as a declaration of its type.
ParameterDecl declaration_of(const std::string& key, py::handle fallback, const std::string& unit,
                             const std::string& description, const std::string& type) {
  const std::string kind = !type.empty()                             ? type
                           : py::isinstance<py::bool_>(fallback)     ? "boolean"
                           : py::isinstance<py::int_>(fallback)      ? "integer"
                           : py::isinstance<py::float_>(fallback)    ? "number"
                           : py::isinstance<py::str>(fallback)       ? "string"
                           : py::isinstance<py::sequence>(fallback)  ? "numbers"
                                                                     : "";
  ParameterDecl d;
  if (kind == "number") {
    d = ParameterDecl::number(key, unit, description);
    if (!fallback.is_none()) d = d.fallback(fallback.cast<double>());
  } else if (kind == "integer") {
    d = ParameterDecl::integer(key, unit, description);
    if (!fallback.is_none()) d = d.fallback(fallback.cast<std::int64_t>());
  } else if (kind == "boolean") {
    d = ParameterDecl::boolean(key, description);
    if (!fallback.is_none()) d = d.fallback(fallback.cast<bool>());
  } else if (kind == "string" || kind == "path") {
    d = kind == "string" ? ParameterDecl::string(key, description) : ParameterDecl::path(key, description);
    if (!fallback.is_none()) d = d.fallback(fallback.cast<std::string>().c_str());
  } else if (kind == "numbers") {
    d = ParameterDecl::numbers(key, 0, unit, description);
    if (!fallback.is_none()) d = d.fallback(fallback.cast<std::vector<double>>());
  } else {
    throw InputError(fmt::format("parameter '{}': a default of type {} (give a number, an integer, a boolean, a string "
                                 "or a list of numbers, or type=...)",
                                 key, type_name(fallback)));
  }
  if (fallback.is_none()) d = d.require();
  return d;
}

/// The `parameters` attribute: {name: default} or a list of objects with name, default, unit,
/// description, type, min, max, choices (bodyfit.Parameter).
std::vector<ParameterDecl> declarations_of(py::handle attribute) {
  std::vector<ParameterDecl> out;
  if (attribute.is_none()) return out;
  if (py::isinstance<py::dict>(attribute)) {
    for (auto [key, fallback] : py::reinterpret_borrow<py::dict>(attribute))
      out.push_back(declaration_of(py::str(key), fallback, "", "", ""));
    return out;
  }
  for (py::handle p : attribute) {
    auto get = [&](const char* name) { return py::getattr(p, name, py::none()); };
    auto text = [&](const char* name) { return get(name).is_none() ? std::string() : py::str(get(name)).cast<std::string>(); };
    ParameterDecl d = declaration_of(text("name"), get("default"), text("unit"), text("description"), text("type"));
    if (py::object choices = get("choices"); !choices.is_none()) {
      ParameterDecl c = ParameterDecl::choice(d.key, choices.cast<std::vector<std::string>>(), d.description);
      if (d.string_default) c = c.fallback(d.string_default->c_str());
      c.required = d.required;
      d = c;
    }
    Range range;
    if (py::object min = get("min"); !min.is_none()) range.min = min.cast<double>();
    if (py::object max = get("max"); !max.is_none()) range.max = max.cast<double>();
    if (!range.unbounded()) d = d.within(range);
    out.push_back(std::move(d));
  }
  return out;
}

/// The `outputs` attribute: names (history columns) or objects with name, kind ("metric",
/// "field", "value"), unit, description (bodyfit.Output).
std::vector<OutputDecl> outputs_of(py::handle attribute) {
  std::vector<OutputDecl> out;
  if (attribute.is_none()) return out;
  for (py::handle o : attribute) {
    if (py::isinstance<py::str>(o)) {
      out.push_back(OutputDecl::metric(o.cast<std::string>(), "", ""));
      continue;
    }
    auto text = [&](const char* name, const char* fallback) {
      py::object v = py::getattr(o, name, py::none());
      return v.is_none() ? std::string(fallback) : py::str(v).cast<std::string>();
    };
    const std::string kind = text("kind", "metric"), name = text("name", ""), unit = text("unit", ""),
                      description = text("description", "");
    if (kind == "metric") out.push_back(OutputDecl::metric(name, unit, description));
    else if (kind == "field") out.push_back(OutputDecl::vertex_field(name, unit, description));
    else if (kind == "value") out.push_back(OutputDecl::value(name, unit, description));
    else throw InputError(fmt::format("output '{}': kind '{}', expected metric, field or value", name, kind));
  }
  return out;
}

py::object read_parameter(Parameters& p, const ParameterDecl& d) {
  switch (d.type) {
    case ParameterType::Number: return py::float_(p.number(d.key));
    case ParameterType::Integer: return py::int_(p.integer(d.key));
    case ParameterType::Boolean: return py::bool_(p.boolean(d.key));
    case ParameterType::Choice: return py::str(p.choice(d.key));
    case ParameterType::Path: return py::str(p.path(d.key).string());
    case ParameterType::Numbers: return py::cast(p.numbers(d.key));
    default: return py::str(p.string(d.key));
  }
}

std::vector<std::pair<std::string, double>> metrics_of(py::handle value, const std::string& what) {
  std::vector<std::pair<std::string, double>> out;
  if (value.is_none()) return out;
  if (!py::isinstance<py::dict>(value))
    throw InputError(fmt::format("{}: a dict of numbers expected, got a {}", what, type_name(value)));
  for (auto [key, number] : py::reinterpret_borrow<py::dict>(value)) {
    if (!py::isinstance<py::float_>(number) && !py::isinstance<py::int_>(number) &&
        !py::hasattr(number, "__float__"))
      throw InputError(fmt::format("{} '{}': a number expected, got a {}", what, std::string(py::str(key)),
                                   type_name(number)));
    out.emplace_back(py::str(key), number.cast<double>());
  }
  return out;
}

/// compute()'s result: an (n, 3) array (tangential V), an (n,) array (normal speed), or a dict
/// with one of "velocity" / "normal_speed" and optional "metrics" and "fields".
VelocityField velocity_of(py::handle result, std::size_t n) {
  py::handle v = result;
  py::dict extra;
  if (py::isinstance<py::dict>(result)) {
    extra = py::reinterpret_borrow<py::dict>(result);
    for (auto [key, value] : extra) {
      const std::string k = py::str(key);
      if (k != "velocity" && k != "normal_speed" && k != "metrics" && k != "fields")
        throw InputError(fmt::format("compute() returned a dict with key '{}': expected velocity or normal_speed, "
                                     "metrics, fields",
                                     k));
    }
    if (extra.contains("velocity") == extra.contains("normal_speed"))
      throw InputError("compute() returned a dict: give exactly one of 'velocity' (n, 3) and 'normal_speed' (n,)");
    v = extra.contains("velocity") ? extra["velocity"] : extra["normal_speed"];
  }
  if (!py::isinstance<py::array>(v))
    throw InputError(fmt::format("compute() returned a {}: expected a numpy array of shape ({}, 3) (a tangential "
                                 "velocity) or ({},) (a normal speed), or a dict",
                                 type_name(v), n, n));
  VelocityField field;
  if (py::reinterpret_borrow<py::array>(v).ndim() == 2)
    field = VelocityField::tangential(vector_field(v, "compute(): the velocity", n));
  else
    field = VelocityField::normal(scalar_field(v, "compute(): the normal speed", n));
  if (extra.contains("metrics")) field.metrics = metrics_of(extra["metrics"], "compute(): metrics");
  if (extra.contains("fields")) {
    if (!py::isinstance<py::dict>(extra["fields"]))
      throw InputError(fmt::format("compute(): fields: a dict of arrays expected, got a {}", type_name(extra["fields"])));
    for (auto [key, value] : py::reinterpret_borrow<py::dict>(extra["fields"])) {
      const std::string name = py::str(key);
      if (py::isinstance<py::array>(value) && py::reinterpret_borrow<py::array>(value).ndim() == 2)
        field.vector_fields.emplace_back(name, vector_field(value, "compute(): field " + name, n));
      else
        field.point_fields.emplace_back(name, scalar_field(value, "compute(): field " + name, n));
    }
  }
  return field;
}

Review review_of(py::handle result) {
  if (result.is_none()) return Review::accept();
  if (py::isinstance<py::bool_>(result))
    return result.cast<bool>() ? Review::accept() : Review::reject("review() returned False");
  auto get = [&](const char* key) -> py::object {
    if (py::isinstance<py::dict>(result)) {
      auto d = py::reinterpret_borrow<py::dict>(result);
      return d.contains(key) ? py::object(d[key]) : py::object(py::none());
    }
    return py::getattr(result, key, py::none());
  };
  Review r;
  if (py::object accept = get("accept"); !accept.is_none() && !accept.cast<bool>()) r.verdict = Review::Verdict::Reject;
  if (py::object reason = get("reason"); !reason.is_none()) r.reason = py::str(reason);
  if (py::object stop = get("stop"); !stop.is_none()) r.stop = stop.cast<bool>();
  if (py::object dt = get("next_dt"); !dt.is_none()) r.next_dt = dt.cast<double>();
  r.metrics = metrics_of(get("metrics"), "review(): metrics");
  return r;
}

}  // namespace

void bind_model_types(py::module_& m) {
  py::class_<Step>(m, "Step", py::module_local(),
                   "The state a model's method receives (read-only numpy views, valid during the call)")
      .def_property_readonly("n_vertices", [](const Step& s) { return s.mesh().n_vertices(); })
      .def_property_readonly("n_faces", [](const Step& s) { return s.mesh().n_faces(); })
      .def_property_readonly(
          "vertices",
          [](py::object self) {
            const auto& mesh = self.cast<Step&>().mesh();
            return view(mesh.n_vertices() ? &mesh.point(VertexHandle(0))[0] : nullptr, mesh.n_vertices(), 3, self);
          },
          "(n, 3) vertex positions of T^n")
      .def_property_readonly(
          "triangles",
          [](py::object self) {
            auto& s = self.cast<Step&>();
            s.build_faces();
            return view(s.triangles.data(), s.triangles.size() / 3, 3, self);
          },
          "(m, 3) vertex indices of the faces")
      .def_property_readonly(
          "regions",
          [](py::object self) {
            auto& s = self.cast<Step&>();
            s.build_faces();
            return view(s.regions.data(), s.regions.size(), 0, self);
          },
          "(m,) face refs: 3 inside G, 2 outside")
      .def_property_readonly("distance", [](py::object self) { return view(self.cast<Step&>().get().distance(), self); },
                             "(n,) signed geodesic distance to the front, < 0 inside G")
      .def_property_readonly("time", [](const Step& s) { return s.get().time(); })
      .def_property_readonly("dt", [](const Step& s) { return s.get().dt(); })
      .def_property_readonly("iteration", [](const Step& s) { return s.get().iteration(); })
      .def_property_readonly("mesh_size", [](const Step& s) { return s.get().mesh_size(); }, "mean edge length h")
      .def_property_readonly("output_dir", [](const Step& s) { return s.get().output_dir().string(); })
      .def_property_readonly("is_height_field", [](const Step& s) { return s.get().is_height_field(); })
      .def_property_readonly("clock_start", [](const Step& s) { return s.get().clock_start(); })
      .def_property_readonly(
          "active_vertices",
          [](py::object self) {
            const auto active = self.cast<Step&>().get().active_vertices();
            return view(active.data(), active.size(), 0, self);
          },
          "the vertices where V is needed (a narrow band); empty: every vertex")
      .def_property_readonly(
          "band_vertices",
          [](py::object self) {
            const auto band = self.cast<Step&>().get().band_vertices();
            return view(band.data(), band.size(), 0, self);
          },
          "where V can matter: active_vertices in a sub-step, d's band and its ring in a banded state; "
          "empty: every vertex")
      .def_property_readonly("conormal", [](py::object self) { return view(self.cast<Step&>().get().conormal(), self); },
                             "(n, 3) unit conormal ∇_S d / |∇_S d|")
      .def_property_readonly("vertex_normals",
                             [](py::object self) { return view(self.cast<Step&>().get().vertex_normals(), self); })
      .def_property_readonly("surface_normals",
                             [](py::object self) { return view(self.cast<Step&>().get().surface_normals(), self); })
      .def_property_readonly("face_normals",
                             [](py::object self) { return view(self.cast<Step&>().get().face_normals(), self); })
      .def_property_readonly("face_areas",
                             [](py::object self) { return view(self.cast<Step&>().get().face_areas(), self); })
      .def_property_readonly("lumped_mass",
                             [](py::object self) { return view(self.cast<Step&>().get().lumped_mass(), self); })
      .def_property_readonly("front_curvature",
                             [](py::object self) { return view(self.cast<Step&>().get().front_curvature(), self); },
                             "(n,) geodesic curvature of the level sets of d (meaningful near the front)")
      .def(
          "mass_matrix", [](py::object self) { return sparse_matrix(self.cast<Step&>().get().mass_matrix(), self); },
          "P1 mass matrix M of T^n (scipy.sparse.csc_matrix, a view)")
      .def(
          "stiffness_matrix",
          [](py::object self) { return sparse_matrix(self.cast<Step&>().get().stiffness_matrix(), self); },
          "P1 stiffness matrix K of T^n (scipy.sparse.csc_matrix, a view)")
      .def(
          "vertex_gradients",
          [](const Step& s, py::handle u) {
            return copy_of(s.get().vertex_gradients(scalar_field(u, "vertex_gradients(u)", s.mesh().n_vertices())));
          },
          py::arg("u"), "(n, 3) tangential gradient of a P1 field at the vertices")
      .def(
          "face_gradients",
          [](const Step& s, py::handle u) {
            return copy_of(s.get().face_gradients(scalar_field(u, "face_gradients(u)", s.mesh().n_vertices())));
          },
          py::arg("u"), "(m, 3) tangential gradient of a P1 field on the faces")
      .def(
          "divergence",
          [](const Step& s, py::handle v) {
            return copy_of(s.get().divergence(vector_field(v, "divergence(v)", s.mesh().n_vertices())));
          },
          py::arg("v"), "(n,) div_S V at the vertices (weak, lumped)")
      .def(
          "smooth",
          [](const Step& s, py::handle f, double length) -> py::array {
            const std::size_t n = s.mesh().n_vertices();
            if (py::isinstance<py::array>(f) && py::reinterpret_borrow<py::array>(f).ndim() == 2)
              return copy_of(s.get().smooth(vector_field(f, "smooth(f)", n), length));
            return copy_of(s.get().smooth(scalar_field(f, "smooth(f)", n), length));
          },
          py::arg("f"), py::arg("length"), "H¹ smoothing: u solving (M + ℓ²K) u = M f");
}

PythonModel::PythonModel(py::object instance, std::string origin) : origin_(std::move(origin)) {
  py::gil_scoped_acquire gil;
  adopt(std::move(instance));
}

std::unique_ptr<PythonModel> PythonModel::from_case() {
  std::unique_ptr<PythonModel> model(new PythonModel());
  model->from_case_ = true;
  model->description_ = "a velocity model written in Python: the class `class` of the file `module`";
  return model;
}

PythonModel::~PythonModel() {
  if (!instance_) return;
  py::gil_scoped_acquire gil;
  instance_ = py::object();
}

void PythonModel::adopt(py::object instance) {
  instance_ = std::move(instance);
  py::handle type = instance_.get_type();
  const std::string class_name = py::str(type.attr("__name__"));
  if (!py::hasattr(instance_, "compute") || !PyCallable_Check(instance_.attr("compute").ptr()))
    throw PluginError(fmt::format("{}: the model class {} has no compute(step) method", origin_, class_name));
  auto text = [&](const char* attribute, std::string fallback) {
    py::object v = py::getattr(instance_, attribute, py::none());
    return v.is_none() ? fallback : py::str(v).cast<std::string>();
  };
  name_ = text("name", class_name);
  version_ = text("version", "1.0");
  description_ = text("description", "");
  if (description_.empty()) {
    const std::string doc = text("__doc__", "");
    description_ = doc.substr(0, doc.find('\n'));
  }
  try {
    declared_ = declarations_of(py::getattr(instance_, "parameters", py::none()));
    outputs_ = outputs_of(py::getattr(instance_, "outputs", py::none()));
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}: {}", origin_, class_name, e.what()));
  } catch (const py::error_already_set& e) {
    throw InputError(fmt::format("{}: {}: the parameters or outputs cannot be read: {}", origin_, class_name, e.what()));
  }
  needs_.may_reject = py::getattr(instance_, "may_reject", py::bool_(false)).cast<bool>();
  needs_.freeze_velocity = py::getattr(instance_, "freeze_velocity", py::bool_(false)).cast<bool>();
  needs_.whole_surface_distance = py::getattr(instance_, "whole_surface_distance", py::bool_(false)).cast<bool>();
  needs_.remesh_everywhere = py::getattr(instance_, "remesh_everywhere", py::bool_(false)).cast<bool>();
  state_version_ = py::getattr(instance_, "state_version", py::int_(0)).cast<std::uint32_t>();
}

bool PythonModel::has_method(const char* method) const {
  return py::hasattr(instance_, method) && PyCallable_Check(instance_.attr(method).ptr());
}

std::vector<ParameterDecl> PythonModel::parameters() const {
  if (!from_case_) return declared_;
  return {ParameterDecl::path("module", "the Python file that defines the model class").require(),
          ParameterDecl::string("class", "the model class in it (its other keys are that class's parameters)").require()};
}

namespace {

/// Python's exceptions as the engine's: a raise in the model is the model's failure.
template <class F>
auto calling(const std::string& what, F&& f) {
  try {
    return f();
  } catch (py::error_already_set& e) {
    throw PluginError(fmt::format("{} raised an exception:\n{}", what, describe(e)));
  } catch (const py::cast_error& e) {
    throw PluginError(fmt::format("{}: {}", what, e.what()));
  } catch (const InputError& e) {
    throw PluginError(fmt::format("{}: {}", what, e.what()));
  }
}

}  // namespace

void PythonModel::configure(Parameters& p) {
  py::gil_scoped_acquire gil;
  if (from_case_) {
    const std::filesystem::path module = p.path("module");
    const std::string class_name = p.string("class");
    origin_ = module.string();
    py::object type;
    try {
      py::module_ util = py::module_::import("importlib.util");
      py::object spec = util.attr("spec_from_file_location")(module.stem().string(), module.string());
      if (spec.is_none()) throw InputError(fmt::format("{}: not a Python module", module.string()));
      py::object loaded = util.attr("module_from_spec")(spec);
      // Imports beside the module find its neighbours, as when it is run as a script.
      py::module_::import("sys").attr("path").attr("insert")(0, module.parent_path().string());
      spec.attr("loader").attr("exec_module")(loaded);
      if (!py::hasattr(loaded, class_name.c_str()))
        throw InputError(fmt::format("{}: no class '{}' in the module", module.string(), class_name));
      type = loaded.attr(class_name.c_str());
    } catch (py::error_already_set& e) {
      // The file is there (a missing one is the case's error, above): it fails as the model's code.
      if (!std::filesystem::exists(module)) throw InputError(fmt::format("{}: no such file", module.string()));
      throw PluginError(fmt::format("{}: the module cannot be imported:\n{}", module.string(), describe(e)));
    }
    py::object instance = calling(fmt::format("{}: {}()", module.string(), class_name), [&] { return type(); });
    adopt(std::move(instance));
    p.declare(declared_);
  }
  py::dict values;
  for (const ParameterDecl& d : declared_) values[py::str(d.key)] = read_parameter(p, d);
  calling(fmt::format("{}: {}.configure", origin_, name_), [&] {
    if (has_method("configure")) instance_.attr("configure")(values);
    else
      for (auto [key, value] : values) py::setattr(instance_, key, value);
    return 0;
  });
}

VelocityField PythonModel::compute(const StepContext& context) {
  py::gil_scoped_acquire gil;
  StepScope step(context);
  return calling(fmt::format("{}: {}.compute", origin_, name_), [&] {
    py::object result = instance_.attr("compute")(step.object());
    return velocity_of(result, context.mesh().n_vertices());
  });
}

void PythonModel::end_step(const StepOutcome& outcome) {
  py::gil_scoped_acquire gil;
  if (!has_method("end_step")) return;
  calling(fmt::format("{}: {}.end_step", origin_, name_), [&] {
    // Views of the engine's arrays, valid during the call; a namespace, not a class: nothing else.
    py::capsule holder(&outcome, [](void*) {});  // owns nothing: the views are valid during the call
    py::dict d;
    const auto n = outcome.mesh.n_vertices();
    d["vertices"] = view(n ? &outcome.mesh.point(VertexHandle(0))[0] : nullptr, n, 3, holder);
    d["distance"] = view(outcome.distance, holder);
    d["phi_next"] = view(outcome.phi_next, holder);
    d["changed"] = view(outcome.changed.data(), outcome.changed.size(), 0, holder);
    d["time"] = outcome.time;
    d["dt"] = outcome.dt;
    d["attempt"] = outcome.attempt;
    instance_.attr("end_step")(py::module_::import("types").attr("SimpleNamespace")(**d));
    return 0;
  });
}

Review PythonModel::review(const StepContext& candidate, int attempt) {
  py::gil_scoped_acquire gil;
  if (!has_method("review")) return Review::accept();
  StepScope step(candidate);
  return calling(fmt::format("{}: {}.review", origin_, name_),
                 [&] { return review_of(instance_.attr("review")(step.object(), attempt)); });
}

void PythonModel::save_state(ModelState& state) const {
  py::gil_scoped_acquire gil;
  if (!has_method("save_state")) return;
  calling(fmt::format("{}: {}.save_state", origin_, name_), [&] {
    py::object saved = instance_.attr("save_state")();
    state.version = state_version_;
    // Any picklable object comes back as it was.
    if (!saved.is_none())
      state.set("python.pickle", py::module_::import("pickle").attr("dumps")(saved, 4).cast<std::string>());
    return 0;
  });
}

void PythonModel::load_state(const ModelState& state) {
  py::gil_scoped_acquire gil;
  if (!has_method("load_state")) return;
  if (state.version != state_version_)
    throw InputError(fmt::format("{}: the checkpoint holds state version {} of model '{}', which is at version {}",
                                 origin_, state.version, name_, state_version_));
  calling(fmt::format("{}: {}.load_state", origin_, name_), [&] {
    py::object saved = py::none();
    if (state.has("python.pickle"))
      saved = py::module_::import("pickle").attr("loads")(py::bytes(state.string("python.pickle")));
    instance_.attr("load_state")(saved);
    return 0;
  });
}

void PythonModel::finish(const StepContext& final_state, ModelOutputs& outputs) {
  py::gil_scoped_acquire gil;
  if (!has_method("finish")) return;
  StepScope step(final_state);
  calling(fmt::format("{}: {}.finish", origin_, name_), [&] {
    py::object values = instance_.attr("finish")(step.object());
    for (const auto& [name, value] : metrics_of(values, "finish(): values")) outputs.value(name, value);
    return 0;
  });
}

}  // namespace bodyfit::python
