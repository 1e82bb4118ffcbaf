#include <bodyfit/checkpoint_writer.hpp>

#include <bodyfit/fault_injection.hpp>

#include <spdlog/spdlog.h>

#include <utility>

namespace bodyfit {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

CheckpointWriter::CheckpointWriter(std::filesystem::path file, CheckpointCadence cadence, std::string case_text)
    : file_(std::move(file)), cadence_(cadence), case_text_(std::move(case_text)), last_snapshot_(Clock::now()) {}

CheckpointWriter::~CheckpointWriter() {
  try {
    wait();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

bool CheckpointWriter::due(int iteration) const {
  if (cadence_.every > 0 && iteration % cadence_.every == 0) return true;
  return cadence_.seconds > 0 &&
         std::chrono::duration<double>(Clock::now() - last_snapshot_).count() >= cadence_.seconds;
}

double CheckpointWriter::snapshot(const SurfaceMesh& mesh, const RunState& run, const ModelState* model) {
  const auto start = Clock::now();
  const double waited = wait();
  const auto copy = Clock::now();
  take_snapshot(snapshot_, mesh, run, model, case_text_);
  last_snapshot_ = Clock::now();
  last_iteration_ = run.iteration;
  const double total = ms_since(start);
  spdlog::debug("checkpoint of iteration {}: {:.1f} MB, {:.1f} ms on the loop (copy {:.1f}, waiting for the previous "
                "write {:.1f})",
                run.iteration, double(snapshot_.bytes().size()) / 1e6, total, ms_since(copy), waited);
  return total;
}

void CheckpointWriter::start() {
  wait();
  if (snapshot_.bytes().empty()) return;  // nothing taken yet
  worker_ = std::thread([this] {
    set_fault_iteration(snapshot_.iteration());  // this thread writes that iteration's checkpoint
    try {
      const auto start = Clock::now();
      save_checkpoint(file_, snapshot_);
      spdlog::debug("checkpoint of iteration {} written in {:.1f} ms (background)", snapshot_.iteration(),
                    ms_since(start));
    } catch (...) {
      error_ = std::current_exception();
    }
    snapshot_.release();  // written (or failed): not held until the next one
  });
}

double CheckpointWriter::wait() {
  const auto start = Clock::now();
  if (worker_.joinable()) worker_.join();
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  return ms_since(start);
}

}  // namespace bodyfit
