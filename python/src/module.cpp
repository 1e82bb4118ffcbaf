// The bodyfit Python module's native part (_bodyfit): meshes and fields as numpy arrays, the
// stages with the command line's options and checks (<bodyfit/app/stages.hpp>), runs (<bodyfit/app/run_case.hpp>)
// with models written in Python (python_model.hpp). The GIL is released in every stage and run.
#include "arrays.hpp"
#include "python_model.hpp"

#include <bodyfit/app/run_case.hpp>
#include <bodyfit/app/stages.hpp>
#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <memory>
#include <optional>

namespace py = pybind11;
using namespace bodyfit;
using namespace bodyfit::python;

namespace {

/// A mesh for Python: the engine's mesh (shared: views of its arrays keep it alive) and named
/// vertex fields. Stages never change a Mesh: they return a new one.
struct Mesh {
  std::shared_ptr<SurfaceMesh> mesh;
  py::dict fields;
  std::size_t n_vertices() const { return mesh->n_vertices(); }
};

Mesh wrap(SurfaceMesh&& mesh) { return Mesh{std::make_shared<SurfaceMesh>(std::move(mesh)), py::dict()}; }

// ---- options: the command line's checks --------------------------------------------------------

void require(bool ok, const std::string& what) {
  if (!ok) throw InputError(what);
}
void positive(std::optional<double> value, const char* name) {
  if (value) require(std::isfinite(*value) && *value > 0, fmt::format("{}: {} is not a finite number > 0", name, *value));
}

RemeshOptions remesh_options(std::optional<double> hmin, std::optional<double> hmax, std::optional<double> hausd,
                             std::optional<double> hausd_interface, double hgrad, double angle) {
  positive(hmin, "hmin");
  positive(hmax, "hmax");
  positive(hausd, "hausd");
  positive(hausd_interface, "hausd_interface");
  require(std::isfinite(hgrad) && hgrad >= 1, fmt::format("hgrad: {} is not a finite number ≥ 1", hgrad));
  require(std::isfinite(angle), fmt::format("angle: {} is not finite", angle));
  if (hmin && hmax) require(*hmin <= *hmax, fmt::format("hmin: {} exceeds hmax {}", *hmin, *hmax));
  RemeshOptions o;
  o.hmin = hmin.value_or(0);
  o.hmax = hmax.value_or(0);
  o.hausd = hausd.value_or(0);
  o.hausd_interface = hausd_interface.value_or(0);
  o.hgrad = hgrad;
  o.feature_angle = angle;
  return o;
}

// ---- fields ----------------------------------------------------------------------------------------

VtuFields vtu_fields(const Mesh& m) {
  VtuFields out;
  for (auto [key, value] : m.fields) {
    const std::string name = py::str(key);
    auto a = py::reinterpret_borrow<py::array>(value);
    if (a.ndim() == 2) out.point_vectors.emplace_back(name, vector_field(value, "field " + name, m.n_vertices()));
    else out.point_scalars.emplace_back(name, scalar_field(value, "field " + name, m.n_vertices()));
  }
  return out;
}

// ---- runs --------------------------------------------------------------------------------------------

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
      "signed_distance",
      [](const Mesh& m, py::handle phi, std::optional<int> region, double narrow_band) {
        require(phi.is_none() != !region.has_value(), "signed_distance: give either phi or region");
        require(std::isfinite(narrow_band) && narrow_band >= 0,
                fmt::format("narrow_band: {} is not a finite number ≥ 0", narrow_band));
        std::optional<ScalarField> values;
        if (!phi.is_none()) values = scalar_field(phi, "phi", m.n_vertices());
        DistanceOptions options;
        if (narrow_band > 0) options.narrow_band = narrow_band;
        SurfaceMesh mesh = *m.mesh;  // a region distance relabels the faces: the caller's mesh stays
        ScalarField d;
        {
          py::gil_scoped_release release;
          d = distance_stage(mesh, values ? &*values : nullptr, region.value_or(0), options);
        }
        return copy_of(d);
      },
      py::arg("mesh"), py::arg("phi") = py::none(), py::arg("region") = py::none(), py::arg("narrow_band") = 0.0,
      R"(The signed geodesic distance at the vertices (negative inside), as `bodyfit distance`.

mesh         the surface
phi          (n,) level set: the distance to its zero set; or
region       a face ref: the distance to the faces with this ref (its interface: the edges
             between them and the rest)
narrow_band  stop beyond this |d| (those vertices get ±1e300); 0: everywhere

Without an interface (phi of one sign) every value is ±1e300. Returns an (n,) array.)");
  m.def(
      "advect",
      [](const Mesh& m, py::handle phi, py::handle velocity, double time, int steps, int rk, bool p1, double cells,
         double max_substeps) {
        require(std::isfinite(time) && time >= 0, fmt::format("time: {} is not a finite number ≥ 0", time));
        require(steps > 0, fmt::format("steps: {} is not > 0", steps));
        require(rk == 2 || rk == 4, fmt::format("rk: {}, expected 2 or 4", rk));
        require(std::isfinite(cells) && cells > 0, fmt::format("cells: {} is not a finite number > 0", cells));
        require(std::isfinite(max_substeps) && max_substeps >= 0,
                fmt::format("max_substeps: {} is not a finite number ≥ 0", max_substeps));
        const ScalarField values = scalar_field(phi, "phi", m.n_vertices());
        const VectorField v = vector_field(velocity, "velocity", m.n_vertices());
        AdvectionOptions options;
        options.steps = steps;
        options.rk_order = rk;
        options.gradient_correction = !p1;
        options.max_cells_per_substep = cells;
        options.max_substeps = max_substeps;
        ScalarField result;
        {
          py::gil_scoped_release release;
          result = advect_stage(*m.mesh, values, v, time, options);
        }
        return copy_of(result);
      },
      py::arg("mesh"), py::arg("phi"), py::arg("velocity"), py::arg("time"), py::arg("steps") = AdvectionOptions{}.steps,
      py::arg("rk") = AdvectionOptions{}.rk_order, py::arg("p1") = false,
      py::arg("cells") = AdvectionOptions{}.max_cells_per_substep, py::arg("max_substeps") = AdvectionOptions{}.max_substeps,
      R"(Solve dφ/dt + V·∇φ = 0 on the surface over (0, time) by characteristics, as `bodyfit advect`.

mesh          the surface
phi           (n,) level set at the vertices
velocity      (n, 3) tangential velocity at the vertices (frozen over the interval)
time          final time T ≥ 0
steps         outer steps over (0, T)
rk            Runge-Kutta order of the tracing: 2 or 4
p1            plain P1 interpolation at the feet (default: P1 averaged with the vertex-gradient
              Taylor expansions, which removes the O(h²) interpolation bias)
cells         edge lengths crossed per sub-step, at most about
max_substeps  refuse to start when the sub-steps of all characteristics are estimated above
              this (0: no limit)

Returns the (n,) advected level set; NumericalError when a characteristic is lost.)");
  m.def(
      "discretize",
      [](const Mesh& m, py::handle phi, double snap, double snap_fixed, double speck, std::optional<double> hmin,
         std::optional<double> hmax, std::optional<double> hausd, std::optional<double> hausd_interface, double hgrad,
         double angle, bool remesh) {
        require(std::isfinite(snap) && snap >= 0 && snap <= 0.5, fmt::format("snap: {} is not in [0, 0.5]", snap));
        require(std::isfinite(snap_fixed) && snap_fixed >= 0 && snap_fixed <= 0.5,
                fmt::format("snap_fixed: {} is not in [0, 0.5]", snap_fixed));
        require(std::isfinite(speck) && speck >= 0, fmt::format("speck: {} is not a finite number ≥ 0", speck));
        const RemeshOptions options = remesh_options(hmin, hmax, hausd, hausd_interface, hgrad, angle);
        const ScalarField values = scalar_field(phi, "phi", m.n_vertices());
        DiscretizeOptions cut;
        cut.snap_ratio = snap;
        cut.fixed_snap_ratio = snap_fixed;
        cut.speck_area = speck;
        SurfaceMesh mesh = *m.mesh;
        {
          py::gil_scoped_release release;
          discretize_stage(mesh, values, cut, options, remesh);
        }
        return wrap(std::move(mesh));
      },
      py::arg("mesh"), py::arg("phi"), py::arg("snap") = DiscretizeOptions{}.snap_ratio,
      py::arg("snap_fixed") = DiscretizeOptions{}.fixed_snap_ratio, py::arg("speck") = DiscretizeOptions{}.speck_area,
      py::arg("hmin") = py::none(), py::arg("hmax") = py::none(), py::arg("hausd") = py::none(),
      py::arg("hausd_interface") = py::none(), py::arg("hgrad") = RemeshOptions{}.hgrad,
      py::arg("angle") = RemeshOptions{}.feature_angle, py::arg("remesh") = true,
      R"(Cut the zero level set of phi into the mesh, then remesh, as `bodyfit discretize` (mmgs -ls 0).

mesh             the surface
phi              (n,) level set at the vertices, negative inside
snap             put a vertex on the level set when the crossing is closer than this fraction of
                 the edge, in [0, 0.5]
snap_fixed       the same for vertices the remesher cannot move (boundary, ridges, corners,
                 required); the larger of the two applies
speck            give parts of a region smaller than this many h² (h: mean edge length) to the
                 region around them
hmin             smallest edge length (default hmax/20)
hmax             largest edge length (default: the input's resolution, the side of an
                 equilateral triangle of its mean area, measured before the cut)
hausd            allowed distance to the surface and interface (default diagonal/1000)
hausd_interface  allowed distance to the interface curve alone (default hausd)
hgrad            gradation between neighbouring sizes, ≥ 1
angle            ridge detection angle in degrees, ≤ 0 disables
remesh           False: only cut the level set in (thin triangles remain)

Returns a new Mesh: regions 3 (inside) and 2 (outside), the interface as edges.)");
  m.def(
      "remesh",
      [](const Mesh& m, std::optional<double> hmin, std::optional<double> hmax, std::optional<double> hausd,
         std::optional<double> hausd_interface, double hgrad, double angle, int passes, bool full) {
        RemeshOptions options = remesh_options(hmin, hmax, hausd, hausd_interface, hgrad, angle);
        require(passes >= 0, fmt::format("passes: {} is negative", passes));
        options.max_passes = passes;
        options.incremental = !full;
        SurfaceMesh mesh = *m.mesh;
        {
          py::gil_scoped_release release;
          remesh_stage(mesh, options);
        }
        return wrap(std::move(mesh));
      },
      py::arg("mesh"), py::arg("hmin") = py::none(), py::arg("hmax") = py::none(), py::arg("hausd") = py::none(),
      py::arg("hausd_interface") = py::none(), py::arg("hgrad") = RemeshOptions{}.hgrad,
      py::arg("angle") = RemeshOptions{}.feature_angle, py::arg("passes") = RemeshOptions{}.max_passes,
      py::arg("full") = false,
      R"(Remesh to high quality, keeping S, the interface and the features, as `bodyfit remesh` (mmgs).

mesh             the surface
hmin             smallest edge length (default hmax/20)
hmax             largest edge length (default: the input's resolution)
hausd            allowed distance to the surface and interface (default diagonal/1000)
hausd_interface  allowed distance to the interface curve alone (default hausd)
hgrad            gradation between neighbouring sizes, ≥ 1
angle            ridge detection angle in degrees, ≤ 0 disables
passes           cap on the collapse/flip/relocate passes (0: none; they stop when done or when
                 they stop making progress)
full             work on every vertex, not only where the mesh needs change

Returns a new Mesh; InputError when the sizes would make more faces than the budget.)");
  m.def(
      "info_json",
      [](const Mesh& m) {
        py::gil_scoped_release release;
        return to_json(describe_mesh(*m.mesh), "");
      },
      py::arg("mesh"));

  m.def("_run", &run, py::arg("case"), py::arg("out"), py::arg("set"), py::arg("model"), py::arg("progress"),
        py::arg("resume"), py::arg("overwrite"), py::arg("force"), py::arg("verbose"));

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
