#include <bodyfit/error.hpp>
#include <bodyfit/model_guard.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <initializer_list>
#include <cstdint>
#include <thread>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <unistd.h>

namespace bodyfit {
namespace {

// What the crash handler reads: plain data and lock-free atomics (async-signal-safe).
char g_model[128] = "?";
std::atomic<const char*> g_stage{nullptr};
std::atomic<int> g_iteration{-1};
std::atomic<std::int64_t> g_started{0};     // steady-clock ns at the start of the current call
std::atomic<std::int64_t> g_limit_ns{0};    // limit_model_calls (0: none)

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void put(char*& at, const char* end, const char* text) {
  while (*text && at < end) *at++ = *text++;
}

void put_int(char*& at, const char* end, int value) {
  char digits[16];
  int n = 0;
  unsigned u = value < 0 ? 0u - unsigned(value) : unsigned(value);
  do digits[n++] = char('0' + u % 10), u /= 10;
  while (u && n < 15);
  if (value < 0 && at < end) *at++ = '-';
  while (n && at < end) *at++ = digits[--n];
}

const char* signal_name(int signal) {
  switch (signal) {
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGABRT: return "SIGABRT";
  }
  return "a signal";
}

/// "bodyfit: model 'M' <what…> <stage> at iteration N<middle><number><tail>; the checkpoint on disk is
/// intact…" on stderr, with write(2) alone: it is called from signal handlers, atexit and the
/// watchdog.
void report_call(const char* stage, std::initializer_list<const char*> what, const char* middle = "", int number = -1,
                 const char* tail = "") {
  char message[512];
  char* at = message;
  const char* end = message + sizeof message - 1;
  put(at, end, "bodyfit: model '");
  put(at, end, g_model);
  put(at, end, "' ");
  for (const char* words : what) put(at, end, words);
  put(at, end, stage);
  const int iteration = g_iteration.load();
  if (iteration >= 0) put(at, end, " at iteration "), put_int(at, end, iteration);
  put(at, end, middle);
  if (number >= 0) put_int(at, end, number);
  put(at, end, tail);
  put(at, end, iteration >= 0 ? "; the checkpoint on disk is intact: --resume continues from it\n"
                              : "; before the run wrote anything\n");
  [[maybe_unused]] auto written = ::write(STDERR_FILENO, message, std::size_t(at - message));
}

extern "C" void on_crash(int signal) {
  // SA_RESETHAND: the default action is back; re-raised below, the process dies of the signal.
  if (const char* stage = g_stage.load()) report_call(stage, {"crashed (", signal_name(signal), ") in "});
  std::raise(signal);  // a raised (not faulting) signal would otherwise return here
}

/// exit() called by the model: a model failure (exit 4), not the run's end with status 0 and no
/// final state. The checkpoint writer may be mid-write: its temporary is removed by the next run.
extern "C" void on_exit_in_model() {
  const char* stage = g_stage.load();
  if (!stage) return;
  report_call(stage, {"called exit() in "}, ": a model failure");
  ::_exit(int(ExitCode::Plugin));
}

std::string message_of(std::exception_ptr error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "an exception that is not a std::exception";
  }
}

}  // namespace

void report_model_crashes(const std::string& name) {
  const std::size_t n = std::min(name.size(), sizeof g_model - 1);
  std::memcpy(g_model, name.data(), n);
  g_model[n] = '\0';
  static const bool installed = [] {
    // Its own stack, so that a stack overflow in the model is reported too.
    static std::vector<char> stack(std::size_t(std::max<long>(SIGSTKSZ, 64 * 1024)));
    stack_t alternate{};
    alternate.ss_sp = stack.data();
    alternate.ss_size = stack.size();
    ::sigaltstack(&alternate, nullptr);
    struct sigaction action {};
    action.sa_handler = on_crash;
    action.sa_flags = SA_RESETHAND | SA_NODEFER | SA_ONSTACK;
    sigemptyset(&action.sa_mask);
    for (int signal : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::sigaction(signal, &action, nullptr);
    std::atexit(on_exit_in_model);
    return true;
  }();
  (void)installed;
}

PluginCall::PluginCall(const char* stage, int iteration) {
  g_iteration.store(iteration);
  g_started.store(now_ns());
  g_stage.store(stage);
}

void limit_model_calls(double seconds) {
  g_limit_ns.store(seconds > 0 ? std::int64_t(seconds * 1e9) : 0);
  if (!(seconds > 0)) return;
  static const bool started = [] {
    std::thread([] {
      for (;;) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        const std::int64_t limit = g_limit_ns.load();
        const char* stage = g_stage.load();
        if (!limit || !stage || now_ns() - g_started.load() <= limit) continue;
        report_call(stage, {"did not return from "}, " within the limit (--model-timeout ", int(limit / 1000000000),
                    " s): a model failure");
        ::_exit(int(ExitCode::Plugin));
      }
    }).detach();
    return true;
  }();
  (void)started;
}

PluginCall::~PluginCall() { g_stage.store(nullptr); }

GuardedModel::GuardedModel(VelocityModel& model, int iteration, std::uint32_t abi)
    : model_(model), name_(model.name()), iteration_(iteration), step_(iteration), abi_(abi) {}

template <class Call>
auto GuardedModel::guarded(const char* stage, int iteration, Call&& call) const -> decltype(call()) {
  PluginCall marked(stage, iteration);
  auto message = [&] {
    const std::string where = iteration >= 0 ? fmt::format(" at iteration {}", iteration) : std::string();
    return fmt::format("model '{}' failed in {}{}: {}", name_, stage, where, message_of(std::current_exception()));
  };
  try {
    return call();
  } catch (const InputError&) {
    throw InputError(message());  // the model says the user's input is wrong (an open surface…)
  } catch (...) {
    throw PluginError(message());
  }
}

void GuardedModel::configure(Parameters& parameters) {
  guarded("configure", -1, [&] { model_.configure(parameters); });
}

ModelNeeds GuardedModel::needs() const {
  ModelNeeds needs = guarded("needs", iteration_, [&] { return model_.needs(); });
  if (!plugin_has(abi_, kAbiBandNormals)) needs.whole_surface_distance = true;
  if (!plugin_has(abi_, kAbiRemeshWhereChanged)) needs.remesh_everywhere = true;
  return needs;
}

VelocityField GuardedModel::compute(const StepContext& context) {
  iteration_ = step_ = context.iteration();
  return guarded("compute", step_, [&] { return model_.compute(context); });
}

void GuardedModel::end_step(const StepOutcome& outcome) {
  guarded("end_step", step_, [&] { model_.end_step(outcome); });
}

Review GuardedModel::review(const StepContext& candidate, int attempt) {
  iteration_ = candidate.iteration();
  return guarded("review", iteration_, [&] { return model_.review(candidate, attempt); });
}

void GuardedModel::save_state(ModelState& state) const {
  guarded("save_state", iteration_, [&] { model_.save_state(state); });
}

void GuardedModel::load_state(const ModelState& state) {
  guarded("load_state", iteration_, [&] { model_.load_state(state); });
}

void GuardedModel::finish(const StepContext& final_state, ModelOutputs& outputs) {
  guarded("finish", iteration_, [&] { model_.finish(final_state, outputs); });
}

std::vector<Nucleus> GuardedModel::nuclei(const StepContext& state, int attempt) {
  if (!plugin_has(abi_, kAbiNuclei)) return {};
  return guarded("nuclei", step_, [&] {
    std::vector<Nucleus> nuclei = model_.nuclei(state, attempt);
    for (const Nucleus& nucleus : nuclei)
      if (nucleus.vertex < 0 || std::size_t(nucleus.vertex) >= state.mesh().n_vertices() || !(nucleus.radius > 0) ||
          !std::isfinite(nucleus.radius))
        throw std::runtime_error(fmt::format("a nucleus at vertex {} of radius {} (T^n has {} vertices; the radius must "
                                             "be positive and finite)",
                                             nucleus.vertex, nucleus.radius, state.mesh().n_vertices()));
    return nuclei;
  });
}

}  // namespace bodyfit
