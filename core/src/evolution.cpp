#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/evolution.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/step_context.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

namespace bodyfit {
namespace {

class Stopwatch {
 public:
  double lap_ms() {
    auto now = std::chrono::steady_clock::now();
    double ms = std::chrono::duration<double, std::milli>(now - start_).count();
    start_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

std::size_t count_inside(const SurfaceMesh& mesh) {
  std::size_t n = 0;
  for (auto f : mesh.faces()) n += mesh.inside(f);
  return n;
}

constexpr char kMagic[8] = {'B', 'F', 'C', 'K', 'P', 'T', '0', '1'};

template <class T>
void put(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}
template <class T>
T get(std::istream& in, const std::string& name) {
  T value{};
  in.read(reinterpret_cast<char*>(&value), sizeof(T));
  if (!in) throw InputError(fmt::format("{}: truncated checkpoint", name));
  return value;
}

}  // namespace

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::FinalTime: return "final time reached";
    case StopReason::Iterations: return "iteration count reached";
    case StopReason::Vanished: return "the region G vanished";
    case StopReason::Filled: return "the region G fills the whole surface";
    case StopReason::Interrupted: return "interrupted";
  }
  return "?";
}

double mean_edge_length(const SurfaceMesh& mesh) { return edge_length_stats(mesh).mean; }

IterationRecord measure_state(const SurfaceMesh& mesh, int iteration, double time) {
  IterationRecord r;
  r.iteration = iteration;
  r.time = time;
  r.area = region_area(mesh, kInside);
  r.interface_length = interface_length(mesh);
  r.components = region_components(mesh, kInside);
  auto q = quality_stats(mesh);
  r.min_quality = q.min;
  r.mean_quality = q.mean;
  r.vertices = mesh.n_vertices();
  r.faces = mesh.n_faces();
  return r;
}

void mesh_initial_region(SurfaceMesh& surface, const ScalarField& phi, const DiscretizeOptions& discretize_options,
                         const RemeshOptions& remesh_options) {
  if (phi.size() != surface.n_vertices())
    throw InputError(fmt::format("initial level set: {} values for {} vertices", phi.size(), surface.n_vertices()));
  bool negative = false, positive = false;
  for (double v : phi) (v < 0 ? negative : positive) = true;
  if (!negative) throw InputError("initial region: the level set is ≥ 0 everywhere (G(0) is empty)");
  if (!positive) throw InputError("initial region: the level set is < 0 everywhere (G(0) is the whole surface)");
  discretize(surface, phi, discretize_options);
  remesh(surface, remesh_options);
}

EvolutionResult evolve(SurfaceMesh& mesh, VelocityModel& model, const EvolutionOptions& options) {
  if (!(options.dt > 0)) throw InputError(fmt::format("evolution: the time step must be > 0 (got {})", options.dt));
  if (!mesh.has_regions()) throw InputError("evolution: the mesh has no face labelled inside (G is empty)");
  mesh.garbage_collection();
  if (options.canonical_order) canonicalize(mesh);

  EvolutionResult result;
  int n = options.start_iteration;
  double t = options.start_time;
  const double tiny = 1e-9 * options.dt;

  auto stop_with = [&](StopReason reason, std::string message) {
    result.reason = reason;
    result.message = std::move(message);
  };
  auto time_left = [&] { return options.final_time - t > tiny; };
  auto iterations_left = [&] { return options.max_iterations < 0 || n < options.max_iterations; };
  auto stop_requested = [&] { return options.stop && options.stop->load(); };

  bool running = true;
  while (running) {
    if (!time_left()) {
      stop_with(StopReason::FinalTime, fmt::format("final time {} reached", options.final_time));
      break;
    }
    if (!iterations_left()) {
      stop_with(StopReason::Iterations, fmt::format("iteration count {} reached", options.max_iterations));
      break;
    }
    if (stop_requested()) {
      stop_with(StopReason::Interrupted, fmt::format("interrupted after iteration {} (t = {})", n, t));
      break;
    }
    const std::size_t inside = count_inside(mesh);
    if (inside == 0) {
      stop_with(StopReason::Vanished, fmt::format("G vanished at iteration {} (t = {})", n, t));
      break;
    }
    if (inside == mesh.n_faces()) {
      stop_with(StopReason::Filled, fmt::format("G fills the whole surface at iteration {} (t = {})", n, t));
      break;
    }
    double dt = options.dt;
    if (options.final_time - t < dt + tiny) dt = options.final_time - t;  // land exactly on T

    // One step of dt. With the CFL cap, (1)-(3) are repeated in sub-steps on the same mesh T^n:
    // d is recomputed from the advected φ (its zero set kept inside the elements), V from d; the
    // cut and the remesh (4) happen once, at the end of the step.
    IterationRecord record;
    std::vector<std::pair<std::string, double>> metrics;
    int passes = 0;
    double done = 0;  // time advanced within this step
    ScalarField phi_next;
    while (done < dt) {
      const double remaining = dt - done;
      Stopwatch clock;
      // (1) distance and velocity.
      ScalarField d = passes == 0 ? signed_distance_to_region(mesh, options.distance)
                                  : signed_distance(mesh, phi_next, options.distance);
      record.ms.distance += clock.lap_ms();
      StepState state;
      state.mesh = &mesh;
      state.distance = &d;
      state.time = t + done;
      state.dt = remaining;
      state.iteration = n;
      state.output_dir = options.output_dir;
      state.terrain = options.terrain;
      VelocityField field;
      VectorField velocity;
      {
        StepContext context = make_step_context(state);
        field = model.compute(context);
        if (field.kind == VelocityField::Kind::Tangential) {
          velocity = std::move(field.vector);
        } else {
          const VectorField& conormal = context.conormal();
          if (field.normal_speed.size() != mesh.n_vertices())
            throw InputError(fmt::format("model '{}': {} normal speeds for {} vertices", model.name(),
                                         field.normal_speed.size(), mesh.n_vertices()));
          velocity.resize(mesh.n_vertices());
          for (std::size_t i = 0; i < velocity.size(); ++i) velocity[i] = field.normal_speed[i] * conormal[i];
        }
      }
      if (velocity.size() != mesh.n_vertices())
        throw InputError(fmt::format("model '{}': {} velocities for {} vertices", model.name(), velocity.size(),
                                     mesh.n_vertices()));
      double step = remaining;
      if (options.max_cfl > 0) {
        // Equal sub-steps over what remains, each moving no point by more than max_cfl·h.
        double vmax = 0;
        for (const Vec3& v : velocity) vmax = std::max(vmax, v.norm());
        if (!std::isfinite(vmax))
          throw InputError(fmt::format("model '{}': non-finite velocity (max_cfl cannot size the sub-steps)", model.name()));
        const double reach = options.max_cfl * (options.cfl_length > 0 ? options.cfl_length : mean_edge_length(mesh));
        const double ratio = vmax * remaining / reach;
        if (ratio > 1 + 1e-9) step = remaining / std::ceil(ratio - 1e-9);  // 3.0000000000000004 is 3
      }
      record.ms.velocity += clock.lap_ms();
      if (passes == 0) {  // the outputs and the model's statistics are those of the state T^n
        if (options.on_state) options.on_state(StateView{mesh, n, t, d, &velocity, &field.point_fields});
        metrics = std::move(field.metrics);
        record.ms.output += clock.lap_ms();
      }

      // (2)(3) advect the signed distance.
      AdvectionReport advection_report;
      phi_next = advect(mesh, d, velocity, step, options.advection, &advection_report);
      model.end_step(StepOutcome{mesh, d, phi_next, t + done, step});
      record.ms.advect += clock.lap_ms();
      if (advection_report.lost > 0)
        spdlog::warn("iteration {}: {} characteristics lost in advection", n, advection_report.lost);
      ++passes;
      done = step == remaining ? dt : done + step;
      // G vanished or fills S within the step: no front left to measure a distance to.
      const auto [lowest, highest] = std::minmax_element(phi_next.begin(), phi_next.end());
      if (done < dt && (*lowest >= 0 || *highest < 0)) break;
    }

    // (4) cut the new interface into T^n and remesh: T^{n+1}.
    Stopwatch clock;
    discretize(mesh, phi_next, options.discretize);
    record.ms.discretize += clock.lap_ms();
    remesh(mesh, options.remesh);
    if (options.canonical_order) canonicalize(mesh);
    record.ms.remesh += clock.lap_ms();

    ++n;
    t += done;
    IterationRecord measured = measure_state(mesh, n, t);
    measured.dt = dt;
    measured.ms = record.ms;
    measured.metrics = std::move(metrics);
    measured.substeps = passes;
    if (options.max_cfl > 0) measured.metrics.emplace_back("substeps", double(passes));
    clock.lap_ms();  // the output callback's time
    if (options.on_iteration) options.on_iteration(mesh, measured);
    measured.ms.output += clock.lap_ms();
    if (options.log)
      spdlog::info("n={} t={:.5g} |G|={:.6g} |dG|={:.6g} comp={} faces={} qmin={:.3f} ms: vel {:.1f} dist {:.1f} "
                   "adv {:.1f} disc {:.1f} remesh {:.1f} out {:.1f}{}",
                   n, t, measured.area, measured.interface_length, measured.components, measured.faces,
                   measured.min_quality, measured.ms.velocity, measured.ms.distance, measured.ms.advect,
                   measured.ms.discretize, measured.ms.remesh, measured.ms.output,
                   passes > 1 ? fmt::format(" ({} sub-steps)", passes) : std::string());
    result.records.push_back(std::move(measured));
  }

  result.iteration = n;
  result.time = t;
  if (count_inside(mesh) > 0 && count_inside(mesh) < mesh.n_faces())
    result.final_distance = signed_distance_to_region(mesh, options.distance);
  else
    result.final_distance.assign(mesh.n_vertices(), count_inside(mesh) ? -INFINITY : INFINITY);
  if (options.on_state) options.on_state(StateView{mesh, n, t, result.final_distance, nullptr, nullptr});
  model.finish(options.output_dir);
  return result;
}

// ---- checkpoints -------------------------------------------------------------------------------

void write_checkpoint(std::ostream& out, const SurfaceMesh& mesh, int iteration, double time) {
  out.write(kMagic, sizeof kMagic);
  put<std::int64_t>(out, iteration);
  put<double>(out, time);
  put<std::uint64_t>(out, mesh.n_vertices());
  put<std::uint64_t>(out, mesh.n_faces());
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    put(out, p[0]), put(out, p[1]), put(out, p[2]);
    put<std::int32_t>(out, mesh.vertex_ref(v));
    put<char>(out, mesh.corner(v));
    put<char>(out, mesh.required(v));
    put<double>(out, mesh.phi(v));
  }
  for (auto f : mesh.faces()) {
    for (auto v : mesh.fv_range(f)) put<std::int32_t>(out, v.idx());
    put<std::int32_t>(out, mesh.region(f));
  }
  std::uint64_t tagged = 0;
  for (auto e : mesh.edges())
    tagged += mesh.edge_ref(e) != 0 || mesh.interface(e) || mesh.ridge(e) || mesh.required(e);
  put(out, tagged);
  for (auto e : mesh.edges()) {
    if (!(mesh.edge_ref(e) != 0 || mesh.interface(e) || mesh.ridge(e) || mesh.required(e))) continue;
    auto h = mesh.halfedge_handle(e, 0);
    put<std::int32_t>(out, mesh.from_vertex_handle(h).idx());
    put<std::int32_t>(out, mesh.to_vertex_handle(h).idx());
    put<std::int32_t>(out, mesh.edge_ref(e));
    put<char>(out, mesh.interface(e));
    put<char>(out, mesh.ridge(e));
    put<char>(out, mesh.required(e));
  }
}

Checkpoint read_checkpoint(std::istream& in, const std::string& name) {
  char magic[sizeof kMagic];
  in.read(magic, sizeof magic);
  if (!in || !std::equal(magic, magic + sizeof magic, kMagic))
    throw InputError(fmt::format("{}: not a bodyfit checkpoint", name));
  Checkpoint c;
  c.iteration = int(get<std::int64_t>(in, name));
  c.time = get<double>(in, name);
  const auto nv = get<std::uint64_t>(in, name);
  const auto nf = get<std::uint64_t>(in, name);
  if (nv > (1ull << 31) || nf > (1ull << 32)) throw InputError(fmt::format("{}: corrupt checkpoint sizes", name));
  SurfaceMesh& mesh = c.mesh;
  mesh.reserve(nv, nv + nf + 16, nf);
  std::vector<VertexHandle> vertices(nv);
  for (std::uint64_t i = 0; i < nv; ++i) {
    double x = get<double>(in, name), y = get<double>(in, name), z = get<double>(in, name);
    auto v = vertices[i] = mesh.add_vertex(Vec3(x, y, z));
    mesh.vertex_ref(v) = get<std::int32_t>(in, name);
    mesh.corner(v) = get<char>(in, name);
    mesh.required(v) = get<char>(in, name);
    mesh.phi(v) = get<double>(in, name);
  }
  auto vertex = [&](std::int32_t i) {
    if (i < 0 || std::uint64_t(i) >= nv) throw InputError(fmt::format("{}: vertex index out of range", name));
    return vertices[std::size_t(i)];
  };
  for (std::uint64_t i = 0; i < nf; ++i) {
    auto a = vertex(get<std::int32_t>(in, name)), b = vertex(get<std::int32_t>(in, name)),
         cc = vertex(get<std::int32_t>(in, name));
    auto f = mesh.add_face(a, b, cc);
    if (!f.is_valid()) throw InputError(fmt::format("{}: face {} is not manifold", name, i));
    mesh.region(f) = get<std::int32_t>(in, name);
  }
  const auto tagged = get<std::uint64_t>(in, name);
  for (std::uint64_t i = 0; i < tagged; ++i) {
    auto a = vertex(get<std::int32_t>(in, name)), b = vertex(get<std::int32_t>(in, name));
    auto h = mesh.find_halfedge(a, b);
    if (!h.is_valid()) throw InputError(fmt::format("{}: tagged edge {} is not in the mesh", name, i));
    auto e = mesh.edge_handle(h);
    mesh.edge_ref(e) = get<std::int32_t>(in, name);
    mesh.interface(e) = get<char>(in, name);
    mesh.ridge(e) = get<char>(in, name);
    mesh.required(e) = get<char>(in, name);
  }
  return c;
}

void save_checkpoint(const std::filesystem::path& file, const SurfaceMesh& mesh, int iteration, double time) {
  write_atomically(file, [&](std::ostream& out) { write_checkpoint(out, mesh, iteration, time); });
}

Checkpoint load_checkpoint(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw file_error(file, "cannot open checkpoint");
  return read_checkpoint(in, file.string());
}

void canonicalize(SurfaceMesh& mesh) {
  mesh.garbage_collection();
  std::stringstream buffer(std::ios::in | std::ios::out | std::ios::binary);
  write_checkpoint(buffer, mesh, 0, 0);
  mesh = std::move(read_checkpoint(buffer, "canonical copy").mesh);
}

}  // namespace bodyfit
