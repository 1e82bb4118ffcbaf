// The module's stages: signed_distance, advect, discretize, remesh, info, with the command line's
// options, defaults and checks (<bodyfit/app/stages.hpp> does the work for both) (bindings.hpp).
#include "arrays.hpp"
#include "bindings.hpp"
#include "py_mesh.hpp"

#include <bodyfit/app/stages.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

namespace bodyfit::python {
namespace {

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

}  // namespace

void bind_stages(py::module_& m) {
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
}

}  // namespace bodyfit::python
