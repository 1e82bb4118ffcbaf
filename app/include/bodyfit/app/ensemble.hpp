#pragma once
// Ensembles: N members of one case, each with its initial region G(0) placed at a sampled point
// and scenario parameters sampled from the case's [ensemble] table, run anywhere (threads, MPI
// ranks), then reduced as the model declares (OutputDecl::ensemble): its grid outputs combined over
// the members — a share (a probability), a mean, percentiles — and its values tabulated.
//
//   [ensemble]
//   members = 200
//   seed = 7
//   percentiles = [10, 50, 90]
//   [ensemble.region]
//   polygon = [[x, y], ...]   # optional: else the plan-view box of S
//   mask = "mask.asc"         # optional: a raster whose cells > 0 may hold the point
//   radius = 300.0            # of G(0), a disk (default: 2 × the mean edge of S)
//   [ensemble.sample]
//   "model.wind.speed" = {dist = "normal", mean = 5, sd = 1.5, min = 0}
//   "model.wind.direction_deg" = {dist = "uniform", min = 200, max = 250}
//
// A sampled key must be one the case's model reads with these settings (the members' cases are
// checked before any member runs). Every random number of member i is a counter-based hash of
// (seed, i, what is drawn, attempt): a member is the same whatever ran before it, on whichever rank
// or thread, in any order. Each member writes its own files (members/m000042.toml, its record,
// last and atomically: a member is done when it exists; members/m000042.<output>.asc, its grids);
// the reduction reads them in index order, so its outputs are bit-identical for any number of
// ranks or threads and any scheduling.
#include <bodyfit/app/dem.hpp>
#include <bodyfit/app/plan_geometry.hpp>
#include <bodyfit/app/process_group.hpp>
#include <bodyfit/app/raster_io.hpp>
#include <bodyfit/model_outputs.hpp>

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bodyfit {

/// A case key given a distribution by [ensemble.sample].
struct SampledParameter {
  enum class Distribution { Uniform, Normal, LogNormal, Choice };
  std::string key;  ///< dotted case key, e.g. "model.wind.speed"
  Distribution distribution = Distribution::Uniform;
  double a = 0, b = 1;  ///< uniform: min, max; normal: mean, sd; lognormal: mu, sigma of ln x
  /// Choice: the values as TOML text ("\"20ft\"", "6.0"), and their weights (equal when empty).
  /// A member's drawn value is the index of its choice (members.csv shows the value itself).
  std::vector<std::string> choices{};
  std::vector<double> weights{};
  /// Truncation of normal and lognormal draws (redrawn until inside, up to a bound).
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
};

/// Where each member's G(0) is: a disk around a point drawn in a polygon and a mask ([ensemble.region]).
struct PlacementSpec {
  std::vector<std::array<double, 2>> polygon;  ///< empty: the plan-view bounding box of S
  std::filesystem::path mask;                  ///< raster whose cells > 0 may hold the point ("": anywhere)
  double radius = 0;                           ///< radius of the disk (0: 2 × mean edge of S)
  int max_attempts = 10000;                    ///< rejection sampling: then the member fails
};

/// The [ensemble] table of a case.
struct EnsembleSpec {
  std::size_t members = 100;
  std::uint64_t seed = 1;
  PlacementSpec region;
  std::vector<SampledParameter> parameters;  ///< in the table's (sorted) key order
  std::vector<double> percentiles{10, 50, 90};
};

/// Read [ensemble] of a case file after the overrides (`--set`); InputError naming file and line.
EnsembleSpec read_ensemble_spec(const std::filesystem::path& case_file, const std::vector<std::string>& overrides);

/// Where the points may be drawn: the polygon or the surface's plan-view box, on the surface, and
/// the mask.
struct PlacementDomain {
  std::vector<std::array<double, 2>> polygon;  ///< closed implicitly; ≥ 3 points
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
  HeightGrid mask;  ///< cols == 0: no mask
  double radius = 0;
  /// A height field seen from above (its outline, holes included); empty for other surfaces. A
  /// centre must lie on it, and the combined grids have no value off it.
  std::vector<PlanPolygon> footprint;
};
/// The domain of a case (builds S once: its footprint, its box, its mean edge).
PlacementDomain make_placement_domain(const std::filesystem::path& case_file, const std::vector<std::string>& overrides,
                                      const EnsembleSpec& spec);

/// One member's scenario: a pure function of (spec, domain, index).
struct MemberScenario {
  std::size_t index = 0;
  bool placed = false;          ///< false: max_attempts draws missed the domain (the member fails)
  double x = 0, y = 0;          ///< the centre of G(0)
  std::vector<double> values;   ///< one per spec.parameters
  std::vector<std::string> overrides;  ///< "key=value", applied after the user's --set
};
MemberScenario sample_member(const EnsembleSpec& spec, const PlacementDomain& domain, std::size_t index);

/// The counter-based hash behind every draw: splitmix64 chained over (seed, index, stream, draw).
std::uint64_t ensemble_hash(std::uint64_t seed, std::uint64_t index, std::uint64_t stream, std::uint64_t draw);

/// What a member left: its record (members/m000042.toml).
struct MemberRecord {
  std::size_t index = 0;
  bool ok = false;
  double x = 0, y = 0;  ///< the centre of G(0)
  std::vector<std::pair<std::string, double>> parameters;
  std::vector<std::pair<std::string, double>> values;  ///< the model's declared values (OutputDecl::Kind::Value)
  double final_time = 0;
  int iterations = 0;
  std::string stop;   ///< why the evolution stopped (ok members)
  std::string error;  ///< the error (failed members)
};

std::filesystem::path member_record_path(const std::filesystem::path& outdir, std::size_t index);
/// members/m000042.<output>.asc: the member's grid of the output `name`.
std::filesystem::path member_grid_path(const std::filesystem::path& outdir, std::size_t index, std::string_view name);

/// Everything members need, shared by the ranks and threads of one ensemble.
/// The frames of the members' grids seen so far (EnsembleRun::frames); shared by the threads.
struct MemberFrames {
  std::mutex mutex;
  std::map<std::string, std::pair<HeightGrid, std::size_t>, std::less<>> first;  ///< by output: frame, member
};

struct EnsembleRun {
  std::filesystem::path case_file;
  std::vector<std::string> overrides;  ///< the user's --set
  std::filesystem::path outdir;
  EnsembleSpec spec;
  PlacementDomain domain;
  std::string model;                ///< the case's model
  std::vector<OutputDecl> combined; ///< its grid outputs an ensemble combines (OutputDecl::ensemble)
  std::vector<OutputDecl> values;   ///< its values (a column each in members.csv)
  /// Test hook: these members throw a NumericalError instead of running.
  std::vector<std::size_t> inject_failures;
  /// The frame of each combined grid, as the first member of this process to finish gave it: a
  /// member whose grid differs stops the ensemble at once (a grid that depends on a sampled
  /// parameter), instead of at the reduction after every member ran.
  std::shared_ptr<MemberFrames> frames = std::make_shared<MemberFrames>();
};

/// The member's record when it is complete (record readable, its grids present when ok), else none.
bool read_member_record(const EnsembleRun& run, std::size_t index, MemberRecord& record);

/// Check the members' cases before any runs: member 0's case (with its sampled values) must be
/// one its model takes whole (every sampled key read with these settings), and the model must
/// declare a grid output an ensemble combines. Fills run.model, run.combined and run.values.
void check_member_case(EnsembleRun& run);

/// Run member `index` and write its files; false when interrupted by `stop` (nothing recorded).
/// A failing member is recorded as failed, with its error: it never throws for the member's own
/// errors (only for an unwritable output directory).
bool run_member(const EnsembleRun& run, std::size_t index, const std::atomic<bool>* stop);

struct ReduceReport {
  std::size_t ok = 0, failed = 0;
};
/// Read members 0 … N−1 in index order and write, for each combination the model declares, its
/// grid (.asc + .prj, and a GeoTIFF with GDAL; a share also as a picture), and members.csv into
/// run.outdir. InputError when a member is missing or the members' grids differ.
ReduceReport reduce_ensemble(const EnsembleRun& run);

/// `bodyfit ensemble`: what to run and where.
struct EnsembleOptions {
  std::filesystem::path case_file;
  std::vector<std::string> overrides;  ///< --set
  std::filesystem::path outdir;
  std::size_t members = 0;             ///< 0: the case's ensemble.members
  std::optional<std::uint64_t> seed;   ///< none: the case's ensemble.seed
  std::size_t jobs = 1;                ///< members run at once on this rank's threads
  const std::atomic<bool>* stop = nullptr;  ///< raised (SIGINT): members in flight are dropped
  std::vector<std::size_t> inject_failures;  ///< test hook (EnsembleRun::inject_failures)
};
struct EnsembleSummary {
  std::size_t ran = 0, skipped = 0;  ///< on this rank: members run, members found complete
  bool interrupted = false;          ///< on any rank: then nothing is reduced
  bool reduced_here = false;         ///< this rank (0) wrote the reduced outputs
  ReduceReport reduced;
};
/// The members i ≡ rank (mod size) not yet complete, on `jobs` threads, then on rank 0 (once
/// every rank is done) the reduction. Every rank must call it. Rank 0 records the case in
/// outdir/ensemble_case.toml and refuses a directory holding another case's ensemble.
EnsembleSummary run_ensemble(const EnsembleOptions& options, const ProcessGroup& group);

/// Every grid of an ensemble goes out through here: `file` (an ESRI grid + .prj, what scripts
/// and the tests read) and, with GDAL, its GeoTIFF twin (.tif: CRS, NODATA, units, description).
void write_ensemble_raster(const std::filesystem::path& file, const HeightGrid& grid,
                           const RasterMetadata& metadata = {});

}  // namespace bodyfit
