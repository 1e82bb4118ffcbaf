#pragma once
// The velocity-model plugin interface.
//
// A plugin is a shared object exporting three C symbols (use BODYFIT_PLUGIN below):
//   uint32_t bodyfit_plugin_abi();            // kPluginAbi of the headers it was built with
//   bodyfit::VelocityModel* bodyfit_create(); // a new model, owned by the caller
//   void bodyfit_destroy(bodyfit::VelocityModel*);
// The loader checks the ABI before calling anything else (plugin_abi.hpp: what must match). A
// model declares the parameters it takes and the outputs it gives, is created once per run and
// configured once through its declarations; the object lives for the whole run and may keep state.
//
// The life of one step n (docs/guide/writing_models.md has the whole picture):
//   compute(T^n)            V^n (once per CFL sub-step, or once per step with needs().freeze_velocity)
//   end_step(φ^{n+1} on T^n) after each advection, before the cut (optional)
//   nuclei(T^n)             new components of G the step creates, added to φ^{n+1} before the cut (optional)
//   review(candidate T^{n+1}) accept / reject (the driver restores T^n and retries with Δt/2; only
//                          with needs().may_reject) / stop the run / ask for the next Δt
//   save_state / load_state  what the model keeps goes into every checkpoint and comes back on --resume
//   finish(T^N, outputs)    once, with the final state: its declared grids and values
#include <bodyfit/mesh.hpp>
#include <bodyfit/model_outputs.hpp>
#include <bodyfit/model_state.hpp>
#include <bodyfit/nucleus.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/plugin_abi.hpp>

#include <Eigen/SparseCore>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bodyfit {

/// What compute() returns: a tangential vector field V at the vertices, or a normal speed v
/// (then V = v·n_Σ with n_Σ the extended unit conormal, a positive v growing G).
struct VelocityField {
  enum class Kind { Tangential, NormalSpeed };
  Kind kind = Kind::Tangential;
  VectorField vector;        ///< Kind::Tangential: one vector per vertex
  ScalarField normal_speed;  ///< Kind::NormalSpeed: one value per vertex
  /// Scalars the driver adds as columns of history.csv (same names every iteration).
  std::vector<std::pair<std::string, double>> metrics;
  /// Vertex fields the driver adds to this state's VTU (and may colour PNG snapshots with).
  std::vector<std::pair<std::string, ScalarField>> point_fields;
  /// Vector vertex fields for the VTU (ParaView sees them as vectors).
  std::vector<std::pair<std::string, VectorField>> vector_fields;

  static VelocityField tangential(VectorField v) {
    VelocityField f;
    f.kind = Kind::Tangential;
    f.vector = std::move(v);
    return f;
  }
  static VelocityField normal(ScalarField v) {
    VelocityField f;
    f.kind = Kind::NormalSpeed;
    f.normal_speed = std::move(v);
    return f;
  }
};

/// What the surface S was built from (VelocityModel::set_surface): a model's own data in space is
/// checked against it, and its outputs carry its coordinate system.
struct SurfaceSource {
  std::filesystem::path file{};  ///< the file S was made from, when it carries coordinates ("": none)
  std::string crs{};             ///< the system of S's coordinates (WKT; "" when unknown)
  /// The file's own system when the case reprojected it to `crs`; "" when S is in the file's own
  /// system.
  std::string reprojected_from{};
};

class ReferenceSurface;  // projection.hpp

/// Where and when a StepContext made outside a run stands (StepContext::standalone).
struct StandaloneStep {
  double time = 0, dt = 0;
  int iteration = 0;
  std::filesystem::path output_dir;
  bool height_field = false;          ///< StepContext::is_height_field
  std::optional<double> clock_start;  ///< StepContext::clock_start
  const ReferenceSurface* surface = nullptr;  ///< S for StepContext::surface_normals (must outlive it)
};

/// Read-only view of the state at iteration n, with the helpers a model needs. Geometric helpers
/// are computed on first use and cached for the iteration.
class StepContext {
 public:
  struct Impl;
  explicit StepContext(std::unique_ptr<Impl> impl);
  ~StepContext();
  StepContext(StepContext&&) noexcept;

  /// A context outside a run (a model's unit tests, tools); `mesh` and `distance` must outlive it.
  static StepContext standalone(const SurfaceMesh& mesh, const ScalarField& distance,
                                const StandaloneStep& where = {});
  StepContext(const StepContext&) = delete;
  StepContext& operator=(const StepContext&) = delete;

  const SurfaceMesh& mesh() const;     ///< T^n: regions (f:region), interface (e:interface)
  /// Signed geodesic distance d_{G^n}, < 0 inside. In a narrow band (EvolutionOptions::narrow_band,
  /// unless ModelNeeds::whole_surface_distance) exact within the band's width of Σ, which holds
  /// every point the step's characteristics reach; beyond, ±that width.
  const ScalarField& distance() const;
  /// t^n; in a CFL sub-step after the first, the sub-step's own start (t^n + the time advanced):
  /// a model whose V depends on time (data given in time) evaluates it there.
  double time() const;
  double dt() const;                   ///< Δt of this step
  int iteration() const;               ///< n
  double mesh_size() const;            ///< mean edge length h of T^n
  const std::filesystem::path& output_dir() const;  ///< where a model may write its own files
  /// Whether S is a height field z(x, y) (a landscape seen from above).
  bool is_height_field() const;
  /// The vertices where V is needed. In the CFL sub-steps after the first, the driver
  /// works in a narrow band around Σ: it reads V only at these vertices, ignores the metrics and
  /// fields, and distance() is the distance only there (beyond, its sign is right and |d| is at
  /// least the band's width). conormal() is then filled only at these vertices. A model may
  /// compute everywhere anyway (correct, slower). Empty: every vertex (the state's own compute).
  std::span<const int> active_vertices() const;
  /// Where V can matter in this call (sorted): in a sub-step, active_vertices(); in a state whose
  /// d is measured in a band, the band's vertices and their ring (beyond, d is flat and n_Σ 0);
  /// empty when d is known on the whole surface (every vertex). conormal() and surface_normals()
  /// are filled there only.
  std::span<const int> band_vertices() const;
  /// The clock time of t = 0 in seconds since 1970-01-01T00:00:00Z, when the case gives one
  /// ([time] start): t^n is then the date-time clock_start + t^n (clock_time.hpp formats it).
  std::optional<double> clock_start() const;

  const std::vector<double>& face_areas() const;
  const VectorField& face_normals() const;
  const VectorField& vertex_normals() const;
  /// The unit normal of the fixed input surface S at the vertices: S's vertex normals
  /// interpolated at each vertex's closest point of S (ReferenceSurface::smooth_normal). One
  /// function of position whatever T^n is, where vertex_normals() change with every remesh: what a
  /// model whose V depends on S's orientation (a slope) should read. vertex_normals() when the
  /// driver has no reference surface. Filled at band_vertices() only (0 beyond), each normal the
  /// same whichever vertices are asked for.
  const VectorField& surface_normals() const;
  /// Unit conormal n_Σ = ∇_S d / |∇_S d| at the vertices, extended to the whole surface.
  const VectorField& conormal() const;
  /// Per-face and per-vertex tangential gradients of a P1 field.
  VectorField face_gradients(const ScalarField& u) const;
  VectorField vertex_gradients(const ScalarField& u) const;
  /// P1 mass and stiffness matrices on T^n (vertex-indexed). They and smooth() couple every
  /// vertex: asking for them in compute() makes the driver measure d on the whole surface from
  /// then on (as ModelNeeds::whole_surface_distance does from the start).
  const Eigen::SparseMatrix<double>& mass_matrix() const;
  const Eigen::SparseMatrix<double>& stiffness_matrix() const;
  /// The lumped mass: a third of the area of the faces around each vertex (the row sums of M).
  const std::vector<double>& lumped_mass() const;
  /// div_S V at the vertices (surface_fem.hpp, surface_divergence): the weak, lumped form; on the
  /// boundary of an open surface it also holds the flux through the boundary.
  ScalarField divergence(const VectorField& field) const;
  /// The curvature of the level sets of d at the vertices: κ = div_S(∇_S d/|∇_S d|)
  /// (surface_fem.hpp, level_set_curvature; for a front on a surface, its geodesic curvature,
  /// > 0 where G is convex). Singular where ∇_S d vanishes — on the ridges of d, the medial axes
  /// of G and of its complement (the centre of a disk): there κ grows like 1/h and means nothing.
  /// Use it near the front (|d| below the smallest radius of curvature), or clip it. In a band
  /// sub-step, valid at the active vertices only. Computed once per context.
  const ScalarField& front_curvature() const;
  /// H¹ smoothing: u solving (M + ℓ²K) u = M f; for vector fields, component-wise then
  /// projected on the tangent planes. ℓ is a length (0 returns f).
  ScalarField smooth(const ScalarField& f, double length) const;
  VectorField smooth(const VectorField& f, double length) const;

 private:
  std::unique_ptr<Impl> impl_;
};

/// The state after one advection of step n (before the cut): φ^{n+1} on T^n. Models that track
/// something through time (the time each point was reached) use it. With CFL sub-steps there is one per sub-step.
struct StepOutcome {
  const SurfaceMesh& mesh;          ///< T^n
  const ScalarField& distance;      ///< d at the start of this (sub-)step
  const ScalarField& phi_next;      ///< φ at its end, at the vertices of T^n
  double time;                      ///< time at the start of this (sub-)step
  double dt;                        ///< its length
  int attempt;                      ///< 0, then 1, 2… when the step is retried after a rejection
  /// The vertices where phi_next may differ from distance (a narrow band: φ was advected
  /// only there). Empty: anywhere.
  std::span<const int> changed = {};
};

/// What a model needs from the driver (asked once, after configure).
struct ModelNeeds {
  /// The model may reject a candidate T^{n+1}: the driver keeps a copy of T^n during each step
  /// (memory: about one more mesh) so it can restore it and retry with Δt/2.
  bool may_reject = false;
  /// With CFL sub-steps, compute V once per step on T^n and advect with it over every sub-step
  /// (a PDE-based model solves once per step, not once per sub-step).
  bool freeze_velocity = false;
  /// The model reads d (or what is computed from it: the conormal, the front's curvature) farther
  /// from Σ than a step can move it — a statistic over the whole surface, a PDE or a smoothing.
  /// Otherwise (EvolutionOptions::narrow_band) the driver computes d^n only within a band of Σ
  /// that holds what the step can reach: beyond it d is ±the band's width (sign right).
  bool whole_surface_distance = false;
  /// The model computes on the whole mesh (a PDE on the part it bounds): each remesh looks for
  /// poor triangles everywhere. Otherwise it starts work only where the step's cut changed T^n
  /// (G^n's boundary, what the front swept, the new boundary; RemeshOptions::changed), and what
  /// the last remesh left elsewhere is not tried again.
  bool remesh_everywhere = false;
};

/// A model's verdict on a candidate T^{n+1}.
struct Review {
  enum class Verdict { Accept, Reject };
  Verdict verdict = Verdict::Accept;
  std::string reason;    ///< why the candidate is rejected, or why the run stops
  bool stop = false;     ///< end the run: after an accepted candidate T^{n+1} is the final state;
                         ///< after a rejected one, T^n is
  double next_dt = 0;    ///< Δt of the next step (0: keep the driver's); the last step is still
                         ///< shortened to land on the final time
  /// Columns added to the accepted state's history row (after compute()'s metrics).
  std::vector<std::pair<std::string, double>> metrics;

  static Review accept() { return {}; }
  static Review reject(std::string why) {
    Review r;
    r.verdict = Verdict::Reject;
    r.reason = std::move(why);
    return r;
  }
  /// Accept the candidate and stop the run there (converged, budget reached…).
  static Review accept_and_stop(std::string why) {
    Review r;
    r.stop = true;
    r.reason = std::move(why);
    return r;
  }
  bool accepted() const { return verdict == Verdict::Accept; }
};

class VelocityModel {
 public:
  virtual ~VelocityModel() = default;
  virtual std::string_view name() const = 0;
  virtual std::string_view version() const { return "1.0"; }
  virtual std::string_view description() const { return ""; }
  /// The parameters of the model's [model] table, declared once: `bodyfit plugins --describe`
  /// prints them, the docs' reference is made from them, and configure() reads through them.
  virtual std::vector<ParameterDecl> parameters() const { return {}; }
  /// What the model gives: its vertex fields, history columns, grids and files.
  virtual std::vector<OutputDecl> outputs() const { return {}; }
  /// What S was built from, given once before configure(). Default: ignored.
  virtual void set_surface(const SurfaceSource& /*source*/) {}
  /// Take the model's parameters (the [model] table of the case, without `name`), read through
  /// the declarations: p.number("speed"). Throw InputError on a bad value (p.fail names the key).
  /// The driver then refuses every key that was set and not read (Parameters::check_consumed).
  virtual void configure(Parameters& parameters) = 0;
  /// What the model needs from the driver (see ModelNeeds). Default: nothing special.
  virtual ModelNeeds needs() const { return {}; }
  /// V^n on the current mesh.
  virtual VelocityField compute(const StepContext& context) = 0;
  /// Called after each advection (each sub-step, each attempt), before the cut; and once with
  /// dt = 0 when a scheduled region joins G (EvolutionOptions::additions: φ goes from d to
  /// min(d, ψ) on the accepted state, before that union is cut). Default: nothing.
  virtual void end_step(const StepOutcome&) {}
  /// The candidate T^{n+1} (cut and remeshed), as a context: its mesh, d_{G^{n+1}}, time t^n + Δt,
  /// iteration n + 1, dt() the step tried. `attempt` counts earlier rejections of this step.
  /// A rejection is honoured only when needs().may_reject. Default: accept.
  virtual Review review(const StepContext& /*candidate*/, int /*attempt*/) { return Review::accept(); }
  /// Put what the model must keep across a resume into `state` (called at every checkpoint).
  virtual void save_state(ModelState& /*state*/) const {}
  /// Restore it on --resume (after configure, before the first step). Throw InputError on a
  /// state the model cannot read.
  virtual void load_state(const ModelState& /*state*/) {}
  /// Called once when the run ends, with the final state: hand the declared grids and values to
  /// `outputs`, write the model's own files in final_state.output_dir() (when not empty).
  virtual void finish(const StepContext& /*final_state*/, ModelOutputs& /*outputs*/) {}
  /// The names of the files the model may write in the output directory, whatever its settings
  /// (`bodyfit run --overwrite` removes them with the driver's own). Default: the declared files
  /// and grids (both formats).
  virtual std::vector<std::string> output_files() const;
  /// New components of G that the step from T^n creates (ABI 3.1): disks around vertices of T^n,
  /// which no velocity can make (characteristics only move the fronts there are). Asked once per
  /// attempt, after the last advection and before the cut, with T^n and d^n; the driver sets
  /// φ^{n+1} ← min(φ^{n+1}, ψ) (nucleus_level_set) and the review judges the candidate with them.
  /// `attempt` counts the step's rejections (a model may drop a nucleus the review refused).
  /// Default: none.
  virtual std::vector<Nucleus> nuclei(const StepContext& /*state*/, int /*attempt*/) { return {}; }
};

/// The file names of declared outputs: File outputs as named, Grid outputs as <name>.tif, .asc, .prj.
std::vector<std::string> declared_output_files(const std::vector<OutputDecl>& outputs);

}  // namespace bodyfit

#define BODYFIT_PLUGIN_EXPORT extern "C" __attribute__((visibility("default")))

/// Export the C entry points of a plugin whose model class is `ModelClass`.
#define BODYFIT_PLUGIN(ModelClass)                                                          \
  BODYFIT_PLUGIN_EXPORT std::uint32_t bodyfit_plugin_abi() { return ::bodyfit::kPluginAbi; } \
  BODYFIT_PLUGIN_EXPORT ::bodyfit::VelocityModel* bodyfit_create() { return new ModelClass(); } \
  BODYFIT_PLUGIN_EXPORT void bodyfit_destroy(::bodyfit::VelocityModel* model) { delete model; }
