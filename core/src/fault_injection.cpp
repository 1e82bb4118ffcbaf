#include <bodyfit/error.hpp>
#include <bodyfit/fault_injection.hpp>

#include <fmt/format.h>

#include <atomic>
#include <charconv>
#include <csignal>

namespace bodyfit {
namespace {

std::atomic<bool> g_armed{false};
std::string g_point;  // written once by arm_fault, before any thread reaches a point
FaultKind g_kind = FaultKind::Kill;
int g_iteration = -1;
thread_local int t_iteration = -1;

}  // namespace

void arm_fault(const std::string& specification, FaultKind kind) {
  const auto colon = specification.rfind(':');
  int iteration = -1;
  if (colon != std::string::npos && colon > 0) {
    const char* first = specification.data() + colon + 1;
    const char* last = specification.data() + specification.size();
    auto [end, ec] = std::from_chars(first, last, iteration);
    if (ec != std::errc() || end != last || first == last) iteration = -1;
  }
  if (iteration < 0)
    throw InputError(fmt::format("--inject-fault {}: expected POINT:ITERATION (e.g. row:3, rename:history.csv:3)",
                                 specification));
  g_point = specification.substr(0, colon);
  g_iteration = iteration;
  g_kind = kind;
  g_armed.store(true);
}

void set_fault_iteration(int iteration) { t_iteration = iteration; }
int fault_iteration() { return t_iteration; }

bool fault_armed(std::string_view point) {
  return g_armed.load(std::memory_order_relaxed) && t_iteration == g_iteration && point == g_point;
}

void fault_point(std::string_view point) {
  if (!fault_armed(point)) return;
  if (g_kind == FaultKind::IoError)
    throw IoError(fmt::format("{}: injected I/O error at iteration {} (--inject-io-error)", point, t_iteration));
  std::raise(SIGKILL);
}

}  // namespace bodyfit
