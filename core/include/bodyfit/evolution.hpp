#pragma once
// The evolution loop (Algorithm 1 of the paper) as a step lifecycle. Step n, from the state T^n
// where G^n is explicitly meshed (faces labelled kInside, interface edges tagged):
//   1. decide whether to stop (final time, iteration count, interruption, G empty or full, the
//      model's request);
//   2. d^n and V^n (the model's compute; a normal speed v becomes v·n_Σ with the extended conormal),
//      then φ^{n+1} = advect(T^n, d^n, V^n, Δt) — in CFL sub-steps on T^n when max_cfl asks;
//   3. cut the zero level set of φ^{n+1} into T^n and remesh: the candidate T^{n+1};
//   4. the model reviews the candidate (with d^{n+1}): accept, reject, stop, next Δt;
//   5. accept: record, outputs, checkpoint (through the hooks); reject: restore T^n and retry with
//      Δt/2, at most max_rejections times.
// evolution.cpp reads the same way: one function per step.
#include <bodyfit/advection.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/distance.hpp>
#include <bodyfit/levelset_mesher.hpp>
#include <bodyfit/mesh.hpp>
#include <bodyfit/remesh.hpp>
#include <bodyfit/velocity_model.hpp>

#include <atomic>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace bodyfit {

/// Wall-clock milliseconds spent in each stage of one iteration.
struct StageTimes {
  double velocity = 0, distance = 0, advect = 0, discretize = 0, remesh = 0, review = 0, output = 0;
  double total() const { return velocity + distance + advect + discretize + remesh + review + output; }
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
  int rejections = 0;             ///< candidates of this step the model rejected before this one
  double min_quality = 0, mean_quality = 0;
  std::size_t vertices = 0, faces = 0;
  StageTimes ms;
  /// The model's: VelocityField::metrics of T^n, then Review::metrics.
  std::vector<std::pair<std::string, double>> metrics;
};

/// Measures of a mesh with regions (the geometric part of an IterationRecord).
IterationRecord measure_state(const SurfaceMesh& mesh, int iteration, double time);

/// What the output hook sees: a state T^n with d^n and V^n, before the level-set step of
/// iteration n; for the final state V and the model's fields are those of one more compute() on
/// it (when G is neither empty nor the whole surface; else null).
struct StateView {
  const SurfaceMesh& mesh;
  int iteration;
  double time;
  const ScalarField& distance;
  const VectorField* velocity;     ///< may be null (final state with no front)
  const VelocityField* model;      ///< the model's fields and metrics (may be null)
  bool final;                      ///< the last state of the run
};

/// A region that joins G at a given time (a source that starts later). The step that would pass `time` is
/// shortened to end on it; the accepted state at `time` then has φ = min(d, level_set) cut into
/// it and remeshed, before its outputs and checkpoint; the model sees the change as one more
/// end_step with dt = 0 (φ from d to that minimum, on the state before the cut). A region whose
/// time is not after the run's start is taken to be in it already (G(0) or a resumed state).
struct ScheduledRegion {
  double time = 0;
  std::function<double(const Vec3&)> level_set;  ///< negative inside the region
};

/// How to evolve: what a case file sets.
struct EvolutionOptions {
  double dt = 0;                 ///< time step (required, > 0); the last step is shortened to hit final_time
  /// Cap on the CFL number max|V|·Δt/h over the vertices (0: no cap). A step of `dt` whose
  /// largest displacement would exceed max_cfl·h is made of equal sub-steps on the same mesh T^n:
  /// each recomputes d (from the advected φ, signed_distance) and V, then advects; the cut and the
  /// remesh happen once per step. The outputs, the history and the checkpoints stay one per step
  /// of `dt`; the model's compute() and end_step() are called per sub-step (StepContext::dt is
  /// what remains of the step; the mesh, its regions and interface edges are those of T^n, the
  /// distance and the conormal those of the moved front), its metrics are those of the first.
  /// A model with ModelNeeds::freeze_velocity is asked once per step and its V advects every sub-step.
  /// Only the front matters: max|V| is taken over the vertices within the band's width of Σ (see
  /// narrow_band), where the front can be within the step's reach.
  double max_cfl = 0;
  /// Work near the front only. d^n is measured within a band of Σ that holds what the step reads
  /// (±the band's width beyond: StepContext::distance), sized by the last step (1.5× its need) and
  /// widened, d measured again, when a step needs more (a faster front); unless the model asks for
  /// the whole surface (ModelNeeds::whole_surface_distance) or freezes V over CFL sub-steps.
  /// One advection over Δt traces the vertices within reach + 3·ĥ (reach = max|V|·Δt, ĥ the
  /// longest edge), reading d and V within 2·reach + 5·ĥ; with max_cfl the sub-steps after the first
  /// redistance φ, ask the model for V (StepContext::active_vertices) and advect φ in a band of
  /// width 2·max_cfl·h + 5·ĥ around the moving front, tracing the vertices within max_cfl·h + 3·ĥ.
  /// The front cannot leave those within a (sub-)step, so the cut gets the whole surface's φ
  /// wherever it reads it (the vertices beyond keep their sign). A step then costs what the band
  /// holds, not the mesh. false: every stage on the whole surface (the reference the band is
  /// tested against).
  bool narrow_band = true;
  /// With max_cfl: the sub-steps' redistancing keeps φ at the vertices of the faces its zero set
  /// crosses (DistanceOptions::keep_crossings), so that only the advection moves the front. false:
  /// those vertices get the distance to the P1 zero set each sub-step, which shifts the front by
  /// O(h²κ) per sub-step: the result then depends on the number of sub-steps (docs/validation/advection.md, "Sub-steps that converge").
  bool keep_crossings = true;
  /// With max_cfl: compose the sub-steps' characteristics back to the start of the step and
  /// interpolate φ^n once at the composed feet (Advector::start_composition), instead of φ at the
  /// feet of every sub-step. On a steep plane the head then lands 5 % from the exact front at 45
  /// sub-steps per step instead of 16 %; on fronts that merge it changes nothing measurable, so it
  /// is off by default (docs/validation/advection.md, "Sub-steps that converge").
  bool compose_substeps = false;
  double cfl_length = 0;         ///< h of the CFL number (0: the mean edge length of the current mesh)
  /// CFL sub-steps one step may take (0: no limit): a Δt far beyond what the speeds allow is an
  /// InputError at the step that needs more, naming the count, not a run that never ends.
  long max_substeps = 10000;
  double final_time = std::numeric_limits<double>::infinity();
  long max_iterations = -1;      ///< stop when the iteration counter reaches this (−1: no limit)
  int max_rejections = 5;        ///< retries (each with half the Δt) of a step the model rejects
  DistanceOptions distance;
  AdvectionOptions advection;
  /// Snapping in an evolution only within a hair (10⁻³ of an edge), or at vertices the remesher
  /// cannot move (fixed_snap_ratio): the remesher removes the slivers, and a snap moves the interface
  /// by up to snap_ratio·h, which at 0.05 made the front noisy (RMS 4.7e-4 after one step at
  /// h = 0.05, Δt = h; 4.1e-5 without). Specks below 0.1 h² are absorbed (they come from noise in φ
  /// and would pin poor triangles). docs/reference/levelset_mesher.md has the measurements.
  DiscretizeOptions discretize;
  RemeshOptions remesh;          ///< set `reference` so that S never drifts
  std::filesystem::path output_dir;  ///< handed to the model (StepContext::output_dir, finish)
  bool height_field = false;     ///< S is a height field z(x, y) (StepContext::is_height_field)
  /// Seconds since 1970-01-01T00:00:00Z at t = 0 ([time] start; StepContext::clock_start).
  std::optional<double> clock_start;
  /// Regions joining G during the run, in any order (ScheduledRegion).
  std::vector<ScheduledRegion> additions;
  /// Bring T^{n+1} to the form a checkpoint reads back (canonicalize) after each iteration, so a
  /// run resumed from a checkpoint continues exactly like the uninterrupted one.
  bool canonical_order = true;
};

struct EvolutionResult;

/// What the caller observes and controls while a run goes on.
struct EvolutionHooks {
  bool log = true;               ///< an spdlog info line per rejected step and per region joining G
  const std::atomic<bool>* stop = nullptr;  ///< raised by the caller (e.g. SIGINT) to stop cleanly
  /// Output stage: called for every state T^n (see StateView); its time is counted as "output".
  std::function<void(const StateView&)> on_state;
  /// Called after every accepted step with T^{n+1}, its record and where the run stands (for the
  /// history and the checkpoint: RunState::dt is the Δt of the next step).
  std::function<void(const SurfaceMesh&, const IterationRecord&, const RunState&)> on_iteration;
  /// Called once when the run has stopped (whatever the reason), with the final state and the
  /// result, after its on_state and before the model's finish(): final outputs written here are on
  /// disk even when finish() fails.
  std::function<void(const SurfaceMesh&, const EvolutionResult&)> on_end;
  /// Called when an exception is about to leave evolve() while the mesh is still an accepted state
  /// (a failure in the model's compute, end_step or finish, in the advection or in an output
  /// hook), with where the run stands: the caller may checkpoint it. Not called when the mesh is a
  /// candidate (a failure in the cut, the remesh or the review). Its own exceptions are logged.
  std::function<void(const SurfaceMesh&, const RunState&)> on_failure;
  /// Where the model's finish() hands its declared grids and values (a run writes them as files,
  /// an ensemble member keeps them). Null: they are dropped.
  ModelOutputs* outputs = nullptr;

  /// No log, no callbacks (tests, benchmarks).
  static EvolutionHooks quiet() {
    EvolutionHooks hooks;
    hooks.log = false;
    return hooks;
  }
};

enum class StopReason {
  FinalTime,
  Iterations,
  Vanished,
  Filled,
  Interrupted,
  ModelStop,  ///< the model asked (Review::stop): converged, budget reached…
  Rejected,   ///< the model rejected a step max_rejections + 1 times
};
const char* to_string(StopReason reason);

struct EvolutionResult {
  StopReason reason = StopReason::FinalTime;
  std::string message;           ///< human-readable reason
  int iteration = 0;             ///< counter of the final state
  double time = 0;               ///< time of the final state
  ScalarField final_distance;    ///< d_{G^N} on the final mesh
  std::vector<IterationRecord> records;  ///< one per completed iteration (not the initial state)
};

/// Run Algorithm 1 on `mesh` (the state `start` with regions; modified in place into the final
/// mesh). The model must be configured (and its state loaded when resuming). Throws InputError
/// when the input mesh has no region.
EvolutionResult evolve(SurfaceMesh& mesh, VelocityModel& model, const EvolutionOptions& options,
                       const RunState& start = {}, const EvolutionHooks& hooks = {});

/// T^0: cut the zero level set of `phi` into `surface` and remesh it (the region of the case).
void mesh_initial_region(SurfaceMesh& surface, const ScalarField& phi, const DiscretizeOptions& discretize,
                         const RemeshOptions& remesh);

}  // namespace bodyfit
