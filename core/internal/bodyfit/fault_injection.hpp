#pragma once
// Fault injection for tests: kill the process (SIGKILL, nothing flushed, nothing cleaned up) at a
// named write point of a run, at a given iteration — a crash at a known point instead of a race
// with a timer — or fail the write there with an IoError (a full disk, a vanished directory).
// `bodyfit run --inject-fault POINT:N` / `--inject-io-error POINT:N` arm it (docs/reference/running.md lists
// the points).
//
// A point is reached by the thread writing the outputs of an iteration; which iteration that is
// is per thread (the run's loop, the background checkpoint writer), set with set_fault_iteration.
// Unarmed, reaching a point is one relaxed atomic load.
#include <string>
#include <string_view>

namespace bodyfit {

enum class FaultKind { Kill, IoError };
/// Arm the one fault of this process from "POINT:ITERATION" (the point may itself contain ':',
/// e.g. "rename:history.csv:3"). Throws InputError on a malformed specification.
void arm_fault(const std::string& specification, FaultKind kind = FaultKind::Kill);
/// The iteration whose outputs the calling thread is writing (thread-local; −1 before any).
void set_fault_iteration(int iteration);
int fault_iteration();
/// Whether the armed fault is `point` at the calling thread's iteration (a point that needs
/// preparing, e.g. waiting for a background write, prepares only then).
bool fault_armed(std::string_view point);
/// When the armed fault is `point` at the calling thread's iteration: SIGKILL the process, or
/// throw an IoError naming the point.
void fault_point(std::string_view point);

}  // namespace bodyfit
