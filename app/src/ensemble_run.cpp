// An ensemble on the ranks of a process group and the threads of each (ensemble.hpp).
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/app/case_config.hpp>
#include <bodyfit/app/case_identity.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/app/output_lock.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/run_directory.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <tbb/task_arena.h>
#include <toml++/toml.h>

#include <exception>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

namespace bodyfit {
namespace {

namespace fs = std::filesystem;

/// The case an ensemble directory holds, as canonical text: the case file after the overrides,
/// without the member count (a finished ensemble may be extended with more members), with the
/// digests of the files it names (with_input_digests) unless `digests` is false.
std::string ensemble_identity(const fs::path& case_file, const std::vector<std::string>& overrides, bool digests) {
  toml::table table = read_case_table(case_file, overrides);
  if (toml::table* ensemble = table["ensemble"].as_table()) ensemble->erase("members");
  return canonical_case(digests ? with_input_digests(table, case_file.parent_path()) : table);
}

/// Rank 0's preparation of the directory: created, the case recorded (or checked against the
/// one recorded), the leftovers of killed members removed.
void prepare_directory(const EnsembleOptions& options, const std::vector<std::string>& overrides) {
  const fs::path members = options.outdir / "members";
  std::error_code ec;
  fs::create_directories(members, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the output directory ({})", members.string(), ec.message()));
  const std::string identity = ensemble_identity(options.case_file, overrides, true);
  const fs::path recorded = options.outdir / "ensemble_case.toml";
  if (fs::exists(recorded)) {
    std::ifstream in(recorded);
    std::ostringstream text;
    text << in.rdbuf();
    // A directory recorded before the digests existed holds the case without them.
    const bool same = text.str() == identity ||
                      (text.str().find("input_files") == std::string::npos &&
                       text.str() == ensemble_identity(options.case_file, overrides, false));
    if (!same) {
      std::vector<std::string> keys;
      std::vector<CaseChange> changes;
      try {
        changes = case_changes(text.str(), identity);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: {}: remove the file, or use another output directory", recorded.string(),
                                     e.what()));
      }
      for (const CaseChange& change : changes) keys.push_back(change.key);
      throw InputError(fmt::format("{} holds an ensemble of another case (or other --set or --seed values, or an "
                                   "edited data file: {}; see {}): use another output directory",
                                   options.outdir.string(), fmt::join(keys, ", "), recorded.string()));
    }
  } else {
    write_atomically(recorded, [&](std::ostream& out) { out << identity; });
  }
  remove_stale_temporaries(options.outdir);  // a reduction killed while writing
  remove_stale_temporaries(members);
  for (const auto& entry : fs::directory_iterator(members))  // the working directories members once had
    if (entry.path().extension() == ".work") fs::remove_all(entry.path(), ec);
}

/// Whether every rank got through a phase; the first error of this rank is rethrown after the
/// others know (so that no rank waits forever in the next collective).
void agree(const ProcessGroup& group, std::exception_ptr error, const char* phase) {
  const bool everyone = group.all_true(!error);
  if (error) std::rethrow_exception(error);
  if (!everyone) throw IoError(fmt::format("another rank failed while {} (see its messages)", phase));
}

}  // namespace

EnsembleSummary run_ensemble(const EnsembleOptions& options, const ProcessGroup& group) {
  std::vector<std::string> overrides = options.overrides;
  if (options.members > 0) overrides.push_back(fmt::format("ensemble.members={}", options.members));
  if (options.seed) overrides.push_back(fmt::format("ensemble.seed={}", *options.seed));

  EnsembleRun run;
  run.case_file = options.case_file;
  run.overrides = options.overrides;  // the user's: the members' cases (the [ensemble] table is theirs too)
  run.outdir = options.outdir;
  run.inject_failures = options.inject_failures;
  std::exception_ptr error;
  std::optional<OutputLock> lock;  // rank 0 owns the directory for the ensemble's life
  try {
    run.spec = read_ensemble_spec(options.case_file, overrides);
    run.domain = make_placement_domain(options.case_file, options.overrides, run.spec);
    check_member_case(run);
    if (group.rank() == 0) {
      lock.emplace(options.outdir);
      prepare_directory(options, overrides);
    }
  } catch (...) {
    error = std::current_exception();
  }
  agree(group, error, "setting up");

  // This rank's members (round robin), the complete ones skipped: a restart recomputes only those
  // whose record is missing.
  EnsembleSummary summary;
  std::vector<std::size_t> mine;
  for (std::size_t i = std::size_t(group.rank()); i < run.spec.members; i += std::size_t(group.size())) {
    MemberRecord record;
    if (read_member_record(run, i, record)) ++summary.skipped;
    else mine.push_back(i);
  }
  if (summary.skipped)
    spdlog::info("rank {}: {} members already complete, {} to run", group.rank(), summary.skipped, mine.size());

  // Local threads take the next member as they finish one; each member's parallel stages get an
  // equal share of the cores (its results do not depend on how many).
  const std::size_t jobs = std::max<std::size_t>(1, std::min(options.jobs, mine.size()));
  const int share = std::max(1, tbb::this_task_arena::max_concurrency() / int(jobs));
  std::atomic<std::size_t> next{0}, ran{0};
  std::atomic<bool> interrupted{false}, failed{false};
  std::mutex error_mutex;
  auto worker = [&] {
    tbb::task_arena arena(share);
    while (!failed.load() && !(options.stop && options.stop->load())) {
      const std::size_t k = next.fetch_add(1);
      if (k >= mine.size()) return;
      try {
        bool done = false;
        arena.execute([&] { done = run_member(run, mine[k], options.stop); });
        if (done) ++ran;
        else interrupted = true;
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> threads;
  for (std::size_t t = 1; t < jobs; ++t) threads.emplace_back(worker);
  worker();
  for (auto& t : threads) t.join();
  summary.ran = ran.load();
  if (options.stop && options.stop->load()) interrupted = true;
  agree(group, error, "running members");
  summary.interrupted = !group.all_true(!interrupted.load());
  if (summary.interrupted || group.rank() != 0) return summary;

  summary.reduced = reduce_ensemble(run);
  summary.reduced_here = true;
  std::error_code ec;
  fs::remove_all(options.outdir / "frames", ec);  // the members' grid frames, compared while they ran
  return summary;
}

}  // namespace bodyfit
