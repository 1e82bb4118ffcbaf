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
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>

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

// Version 1 stored the faces' corners (read back through add_face, whose cost dominated an
// iteration's remesh stage at 200k faces); version 2 stores OpenMesh's connectivity arrays as they
// are, so reading restores the exact mesh in O(n) and canonicalize() is cheap.
constexpr char kMagicV1[8] = {'B', 'F', 'C', 'K', 'P', 'T', '0', '1'};
constexpr char kMagicV2[8] = {'B', 'F', 'C', 'K', 'P', 'T', '0', '2'};

/// Checkpoint bytes, built in memory and written at once.
class Bytes {
 public:
  template <class T>
  void put(const T& value) {
    data_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void put_raw(const char* bytes, std::size_t size) { data_.append(bytes, size); }
  void reserve(std::size_t size) { data_.reserve(size); }
  const std::string& data() const { return data_; }

 private:
  std::string data_;
};

/// Reading checkpoint bytes: every read is bounds-checked ("truncated checkpoint").
class Cursor {
 public:
  Cursor(const std::string& data, const std::string& name) : data_(data), name_(name) {}
  template <class T>
  T get() {
    if (data_.size() - at_ < sizeof(T)) throw InputError(fmt::format("{}: truncated checkpoint", name_));
    T value{};
    std::memcpy(&value, data_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  /// An element index in [0, size) (or −1 when `allow_none`).
  int index(std::uint64_t size, const char* what, bool allow_none = false) {
    const auto i = get<std::int32_t>();
    if ((i < 0 && !(allow_none && i == -1)) || (i >= 0 && std::uint64_t(i) >= size))
      throw InputError(fmt::format("{}: {} index {} out of range", name_, what, i));
    return i;
  }
  [[noreturn]] void corrupt(const std::string& what) const {
    throw InputError(fmt::format("{}: corrupt checkpoint: {}", name_, what));
  }
  const std::string& name() const { return name_; }

 private:
  const std::string& data_;
  std::string name_;
  std::size_t at_ = 0;
};

void put_vertex(Bytes& out, const SurfaceMesh& mesh, VertexHandle v) {
  const Vec3& p = mesh.point(v);
  out.put(p[0]), out.put(p[1]), out.put(p[2]);
  out.put<std::int32_t>(mesh.vertex_ref(v));
  out.put<char>(mesh.corner(v));
  out.put<char>(mesh.required(v));
  out.put<double>(mesh.phi(v));
}

/// The fields put_vertex wrote, into the existing vertex v.
void get_vertex(Cursor& in, SurfaceMesh& mesh, VertexHandle v) {
  const double x = in.get<double>(), y = in.get<double>(), z = in.get<double>();
  mesh.set_point(v, Vec3(x, y, z));
  mesh.vertex_ref(v) = in.get<std::int32_t>();
  mesh.corner(v) = in.get<char>();
  mesh.required(v) = in.get<char>();
  mesh.phi(v) = in.get<double>();
}

void put_edge_tags(Bytes& out, const SurfaceMesh& mesh, EdgeHandle e) {
  out.put<std::int32_t>(mesh.edge_ref(e));
  out.put<char>(mesh.interface(e));
  out.put<char>(mesh.ridge(e));
  out.put<char>(mesh.required(e));
}

void get_edge_tags(Cursor& in, SurfaceMesh& mesh, EdgeHandle e) {
  mesh.edge_ref(e) = in.get<std::int32_t>();
  mesh.interface(e) = in.get<char>();
  mesh.ridge(e) = in.get<char>();
  mesh.required(e) = in.get<char>();
}

/// Version 1: vertices, faces by corners (rebuilt with add_face), tagged edges by their ends.
SurfaceMesh read_v1(Cursor& in, std::uint64_t nv, std::uint64_t nf) {
  SurfaceMesh mesh;
  mesh.reserve(nv, nv + nf + 16, nf);
  std::vector<VertexHandle> vertices(nv);
  for (std::uint64_t i = 0; i < nv; ++i) get_vertex(in, mesh, vertices[i] = mesh.new_vertex(Vec3(0, 0, 0)));
  for (std::uint64_t i = 0; i < nf; ++i) {
    const int a = in.index(nv, "vertex"), b = in.index(nv, "vertex"), c = in.index(nv, "vertex");
    const auto f = mesh.add_face(vertices[a], vertices[b], vertices[c]);
    if (!f.is_valid()) throw InputError(fmt::format("{}: face {} is not manifold", in.name(), i));
    mesh.region(f) = in.get<std::int32_t>();
  }
  const auto tagged = in.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < tagged; ++i) {
    const int a = in.index(nv, "vertex"), b = in.index(nv, "vertex");
    const auto h = mesh.find_halfedge(vertices[a], vertices[b]);
    if (!h.is_valid()) throw InputError(fmt::format("{}: tagged edge {} is not in the mesh", in.name(), i));
    get_edge_tags(in, mesh, mesh.edge_handle(h));
  }
  return mesh;
}

/// Version 2: OpenMesh's connectivity arrays restored as they were written, then checked (each
/// face a 3-cycle of its own halfedges, consecutive halfedges meeting at a vertex, each vertex's
/// halfedge leaving it), so a corrupt file is an error rather than a broken mesh.
SurfaceMesh read_v2(Cursor& in, std::uint64_t nv, std::uint64_t ne, std::uint64_t nf) {
  SurfaceMesh mesh;
  // All arrays at once (one resize per property, not one per element), then filled in place.
  mesh.resize(nv, ne, nf);
  const std::uint64_t nh = 2 * ne;
  for (std::uint64_t i = 0; i < nv; ++i) {
    const VertexHandle v{int(i)};
    get_vertex(in, mesh, v);
    mesh.set_halfedge_handle(v, HalfedgeHandle(in.index(nh, "halfedge", true)));
  }
  for (std::uint64_t e = 0; e < ne; ++e) {
    for (int side = 0; side < 2; ++side) {
      const HalfedgeHandle h{int(2 * e + side)};
      mesh.set_vertex_handle(h, VertexHandle(in.index(nv, "vertex")));
      mesh.set_next_halfedge_handle(h, HalfedgeHandle(in.index(nh, "halfedge")));
      mesh.set_face_handle(h, FaceHandle(in.index(nf, "face", true)));
    }
    get_edge_tags(in, mesh, EdgeHandle(int(e)));
  }
  for (std::uint64_t f = 0; f < nf; ++f) {
    const FaceHandle fh{int(f)};
    mesh.set_halfedge_handle(fh, HalfedgeHandle(in.index(nh, "halfedge")));
    mesh.region(fh) = in.get<std::int32_t>();
  }
  for (std::uint64_t h = 0; h < nh; ++h) {
    const HalfedgeHandle hh{int(h)};
    if (mesh.to_vertex_handle(hh) != mesh.from_vertex_handle(mesh.next_halfedge_handle(hh)))
      in.corrupt(fmt::format("halfedge {} and its next do not meet", h));
  }
  for (std::uint64_t f = 0; f < nf; ++f) {
    HalfedgeHandle h = mesh.halfedge_handle(FaceHandle(int(f)));
    for (int k = 0; k < 3; ++k, h = mesh.next_halfedge_handle(h))
      if (mesh.face_handle(h).idx() != int(f)) in.corrupt(fmt::format("face {} is not a triangle of its halfedges", f));
    if (h != mesh.halfedge_handle(FaceHandle(int(f)))) in.corrupt(fmt::format("face {} is not a triangle", f));
  }
  for (std::uint64_t v = 0; v < nv; ++v) {
    const HalfedgeHandle h = mesh.halfedge_handle(VertexHandle(int(v)));
    if (h.is_valid() && mesh.from_vertex_handle(h).idx() != int(v))
      in.corrupt(fmt::format("vertex {}'s halfedge does not leave it", v));
  }
  return mesh;
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

namespace {

/// Whether elements are marked deleted (the arrays would then not be the mesh).
bool has_deleted(const SurfaceMesh& mesh) {
  for (auto v : mesh.all_vertices())
    if (mesh.status(v).deleted()) return true;
  for (auto e : mesh.all_edges())
    if (mesh.status(e).deleted()) return true;
  for (auto f : mesh.all_faces())
    if (mesh.status(f).deleted()) return true;
  return false;
}

std::string encode_checkpoint(const SurfaceMesh& mesh, int iteration, double time) {
  if (has_deleted(mesh)) throw std::logic_error("write_checkpoint: the mesh must be garbage-collected");
  Bytes out;
  // Header, then per vertex 3 doubles + int + 2 chars + double + int, per edge 6 ints + int + 3
  // chars, per face 2 ints.
  out.reserve(48 + 42 * mesh.n_vertices() + 31 * mesh.n_edges() + 8 * mesh.n_faces());
  out.put_raw(kMagicV2, sizeof kMagicV2);
  out.put<std::int64_t>(iteration);
  out.put<double>(time);
  out.put<std::uint64_t>(mesh.n_vertices());
  out.put<std::uint64_t>(mesh.n_edges());
  out.put<std::uint64_t>(mesh.n_faces());
  for (auto v : mesh.vertices()) {
    put_vertex(out, mesh, v);
    out.put<std::int32_t>(mesh.halfedge_handle(v).idx());
  }
  for (auto e : mesh.edges()) {
    for (int side = 0; side < 2; ++side) {
      const auto h = mesh.halfedge_handle(e, side);
      out.put<std::int32_t>(mesh.to_vertex_handle(h).idx());
      out.put<std::int32_t>(mesh.next_halfedge_handle(h).idx());
      out.put<std::int32_t>(mesh.face_handle(h).idx());
    }
    put_edge_tags(out, mesh, e);
  }
  for (auto f : mesh.faces()) {
    out.put<std::int32_t>(mesh.halfedge_handle(f).idx());
    out.put<std::int32_t>(mesh.region(f));
  }
  return out.data();
}

Checkpoint decode_checkpoint(const std::string& data, const std::string& name) {
  Cursor in(data, name);
  char magic[8];
  for (char& c : magic) c = in.get<char>();
  const bool v1 = std::equal(magic, magic + 8, kMagicV1), v2 = std::equal(magic, magic + 8, kMagicV2);
  if (!v1 && !v2) throw InputError(fmt::format("{}: not a bodyfit checkpoint", name));
  Checkpoint c;
  c.iteration = int(in.get<std::int64_t>());
  c.time = in.get<double>();
  const auto nv = in.get<std::uint64_t>();
  const auto ne = v2 ? in.get<std::uint64_t>() : 0;
  const auto nf = in.get<std::uint64_t>();
  if (nv > (1ull << 31) || ne > (1ull << 30) || nf > (1ull << 31))
    throw InputError(fmt::format("{}: corrupt checkpoint sizes", name));
  c.mesh = v2 ? read_v2(in, nv, ne, nf) : read_v1(in, nv, nf);
  return c;
}

}  // namespace

void write_checkpoint(std::ostream& out, const SurfaceMesh& mesh, int iteration, double time) {
  const std::string data = encode_checkpoint(mesh, iteration, time);
  out.write(data.data(), std::streamsize(data.size()));
}

Checkpoint read_checkpoint(std::istream& in, const std::string& name) {
  const std::string data{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return decode_checkpoint(data, name);
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
  if (has_deleted(mesh)) mesh.garbage_collection();  // OpenMesh's costs as much as the copy even when idle
  mesh = std::move(decode_checkpoint(encode_checkpoint(mesh, 0, 0), "canonical copy").mesh);
}

}  // namespace bodyfit
