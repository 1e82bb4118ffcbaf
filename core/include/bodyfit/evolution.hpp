#pragma once
// The evolution loop (Algorithm 1 of the paper). Iteration n, on the mesh T^n where G^n is
// explicitly meshed (faces labelled kInside, interface edges tagged):
//   1. d^n = signed distance to G^n; the model computes V^n (a normal speed v becomes v·n_Σ with
//      the context's extended conormal);
//   2-3. φ^{n+1} = advect(T^n, d^n, V^n, Δt); model.end_step(...);
//   4. discretize(T^n, φ^{n+1}) then remesh → T^{n+1}.
// With max_cfl > 0, steps 1-3 are repeated in sub-steps on T^n as the CFL cap asks, 4 runs once.
// The loop stops at the final time or iteration count, when G vanishes or fills S, or when the
// caller's stop flag is raised (checked between iterations, after that iteration's outputs).
#include <bodyfit/advection.hpp>
#include <bodyfit/distance.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/mesh.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/velocity_model.hpp>

#include <atomic>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace bodyfit {

/// Wall-clock milliseconds spent in each stage of one iteration.
struct StageTimes {
  double velocity = 0, distance = 0, advect = 0, discretize = 0, remesh = 0, output = 0;
  double total() const { return velocity + distance + advect + discretize + remesh + output; }
};

/// One row of the history: the state T^n at time t^n and what it cost to produce it (row 0 is
/// the initial state; row n+1 carries the stage times and model metrics of iteration n).
struct IterationRecord {
  int iteration = 0;
  double time = 0;
  double dt = 0;                  ///< the step that produced this state (0 for the initial state)
  double area = 0;                ///< |G|
  double interface_length = 0;    ///< |∂G|
  int components = 0;             ///< connected components of G
  int substeps = 1;               ///< sub-steps (1-3) that made this step (EvolutionOptions::max_cfl)
  double min_quality = 0, mean_quality = 0;
  std::size_t vertices = 0, faces = 0;
  StageTimes ms;
  std::vector<std::pair<std::string, double>> metrics;  ///< the model's, from VelocityField::metrics
};

/// Measures of a mesh with regions (the geometric part of an IterationRecord).
IterationRecord measure_state(const SurfaceMesh& mesh, int iteration, double time);

/// What the output callback sees: T^n with d^n and V^n, before the level-set step of iteration n.
/// For the last state (after the final iteration) `velocity` is null and d is that of T^N.
struct StateView {
  const SurfaceMesh& mesh;
  int iteration;
  double time;
  const ScalarField& distance;
  const VectorField* velocity;  ///< null for the final state
  const std::vector<std::pair<std::string, ScalarField>>* model_fields;  ///< may be null
};

struct EvolutionOptions {
  double dt = 0;                 ///< time step (required, > 0); the last step is shortened to hit final_time
  /// Cap on the CFL number max|V|·Δt/h over the vertices (0: no cap). A step of `dt` whose
  /// largest displacement would exceed max_cfl·h is made of equal sub-steps on the same mesh T^n:
  /// each recomputes d (from the advected φ, signed_distance) and V, then advects; the cut and the
  /// remesh happen once per step. The outputs, the history and the checkpoints stay one per step
  /// of `dt`; the model's compute() and end_step() are called per sub-step (StepContext::dt is
  /// what remains of the step; the mesh, its regions and interface edges are those of T^n, the
  /// distance and the conormal those of the moved front), its metrics are those of the first.
  double max_cfl = 0;
  double cfl_length = 0;         ///< h of the CFL number (0: the mean edge length of the current mesh)
  double final_time = std::numeric_limits<double>::infinity();
  long max_iterations = -1;      ///< stop when the iteration counter reaches this (−1: no limit)
  int start_iteration = 0;       ///< counter and time of the input mesh (≠ 0 when resuming)
  double start_time = 0;
  DistanceOptions distance;
  AdvectionOptions advection;
  /// Snapping in an evolution only within a hair (10⁻³ of an edge), or at vertices the remesher
  /// cannot move (fixed_snap_ratio): the remesher removes the slivers, and a snap moves the interface
  /// by up to snap_ratio·h, which at 0.05 made the front noisy (RMS 4.7e-4 after one step at
  /// h = 0.05, Δt = h; 4.1e-5 without). Specks below 0.1 h² are absorbed (they come from noise in φ
  /// and would pin poor triangles). docs/levelset_mesher.md has the measurements.
  DiscretizeOptions discretize{.snap_ratio = 1e-3, .speck_area = 0.1};
  RemeshOptions remesh;          ///< set `reference` so that S never drifts
  std::filesystem::path output_dir;  ///< handed to the model (StepContext::output_dir, finish)
  bool terrain = false;          ///< S is a height field (StepContext::is_terrain)
  /// Rebuild T^{n+1} from its arrays after each iteration, in the order a checkpoint is read back:
  /// a run resumed from a checkpoint then continues exactly like the uninterrupted one.
  bool canonical_order = true;
  bool log = true;               ///< one spdlog info line per iteration
  const std::atomic<bool>* stop = nullptr;  ///< raised by the caller (e.g. SIGINT) to stop cleanly
  /// Output stage: called for every state T^n (see StateView); its time is counted as "output".
  std::function<void(const StateView&)> on_state;
  /// Called after every completed iteration with T^{n+1} and its record (history, checkpoint).
  std::function<void(const SurfaceMesh&, const IterationRecord&)> on_iteration;
};

enum class StopReason { FinalTime, Iterations, Vanished, Filled, Interrupted };
const char* to_string(StopReason reason);

struct EvolutionResult {
  StopReason reason = StopReason::FinalTime;
  std::string message;           ///< human-readable reason
  int iteration = 0;             ///< counter of the final state
  double time = 0;               ///< time of the final state
  ScalarField final_distance;    ///< d_{G^N} on the final mesh
  std::vector<IterationRecord> records;  ///< one per completed iteration (not the initial state)
};

/// Run Algorithm 1 on `mesh` (T^n with regions; modified in place into the final mesh).
/// The model must be configured. Throws InputError when the input mesh has no region.
EvolutionResult evolve(SurfaceMesh& mesh, VelocityModel& model, const EvolutionOptions& options);

/// T^0: cut the zero level set of `phi` into `surface` and remesh it (the region of the case).
void mesh_initial_region(SurfaceMesh& surface, const ScalarField& phi, const DiscretizeOptions& discretize,
                         const RemeshOptions& remesh);

/// Mean edge length of a mesh (the h of Δt = c·h).
double mean_edge_length(const SurfaceMesh& mesh);

// ---- checkpoints -------------------------------------------------------------------------------
// A binary snapshot of the state after a completed iteration: the mesh with every tag and φ, the
// iteration counter and the time, with doubles stored bit-exactly.

struct Checkpoint {
  SurfaceMesh mesh;
  int iteration = 0;
  double time = 0;
};
void write_checkpoint(std::ostream& out, const SurfaceMesh& mesh, int iteration, double time);
/// Atomically (write to a temporary, then rename).
void save_checkpoint(const std::filesystem::path& file, const SurfaceMesh& mesh, int iteration, double time);
Checkpoint read_checkpoint(std::istream& in, const std::string& name = "checkpoint");
Checkpoint load_checkpoint(const std::filesystem::path& file);
/// Rebuild `mesh` from its vertex and face arrays exactly as read_checkpoint would.
void canonicalize(SurfaceMesh& mesh);

}  // namespace bodyfit
