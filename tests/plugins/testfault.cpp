// A test model that fails on request: constant normal speed, and at one stage of one iteration it
// throws (a std::runtime_error, an InputError, an int), crashes (SIGSEGV, SIGFPE), calls exit(0) or
// returns a broken field (a NaN, the wrong size); with BODYFIT_TESTFAULT_CREATE=segv or exit in the
// environment its constructor crashes or exits (a plugin that cannot even be created). Its state (the iteration reached, the computes made) goes
// through the checkpoint, so that save_state and load_state can fail too.
#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>
#include <bodyfit/velocity_model.hpp>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <stdexcept>

namespace {

using namespace bodyfit;

class FaultModel final : public VelocityModel {
 public:
  FaultModel() {
    if (const char* how = std::getenv("BODYFIT_TESTFAULT_CREATE")) {
      if (std::string(how) == "segv") std::raise(SIGSEGV);
      if (std::string(how) == "exit") std::exit(0);
    }
  }
  std::string_view name() const override { return "testfault"; }
  std::vector<ParameterDecl> parameters() const override {
    return {ParameterDecl::number("speed", "", "normal speed").fallback(1.0),
            ParameterDecl::choice("stage", {"none", "configure", "compute", "end_step", "review", "save_state",
                                            "load_state", "finish"},
                                  "where the model fails")
                .fallback("none"),
            ParameterDecl::integer("at", "", "the iteration it fails at").fallback(0).at_least(0),
            ParameterDecl::choice("how", {"runtime_error", "input_error", "int", "segv", "fpe", "not_finite", "size", "exit", "metric_name"},
                                  "how it fails")
                .fallback("runtime_error")};
  }
  void configure(Parameters& p) override {
    speed_ = p.number("speed");
    stage_ = p.choice("stage");
    at_ = p.integer("at");
    how_ = p.choice("how");
    if (stage_ == "configure") fail();
  }

  VelocityField compute(const StepContext& context) override {
    step_ = context.iteration();
    ++computes_;
    auto field = VelocityField::normal(ScalarField(context.mesh().n_vertices(), speed_));
    if (stage_ == "compute" && step_ == at_) {
      if (how_ == "not_finite") field.normal_speed[field.normal_speed.size() / 2] = std::nan("");
      else if (how_ == "size") field.normal_speed.pop_back();
      else if (how_ == "metric_name") field.metrics.emplace_back("a,b\nc", 1.0);
      else fail();
    }
    return field;
  }
  void end_step(const StepOutcome&) override {
    if (stage_ == "end_step" && step_ == at_) fail();
  }
  Review review(const StepContext& candidate, int) override {
    if (stage_ == "review" && candidate.iteration() == at_) fail();
    state_ = candidate.iteration();
    return Review::accept();
  }
  void save_state(ModelState& state) const override {
    if (stage_ == "save_state" && state_ == at_) fail();
    state.version = 1;
    state.set("state", std::vector<std::int64_t>{state_, computes_});
  }
  void load_state(const ModelState& state) override {
    const auto& values = state.integers("state");
    state_ = values.at(0), computes_ = values.at(1);
    if (stage_ == "load_state" && state_ == at_) fail();
  }
  void finish(const StepContext&, ModelOutputs&) override {
    if (stage_ == "finish" && state_ == at_) fail();
  }

 private:
  [[noreturn]] void fail() const {
    if (how_ == "input_error") throw InputError("an input error from " + stage_);
    if (how_ == "int") throw 42;
    // The crashes are raised, not provoked: a null store or a division by zero is undefined
    // behaviour, at which the sanitize stage's UBSan stops before any signal is sent.
    if (how_ == "segv") std::raise(SIGSEGV);
    if (how_ == "fpe") std::raise(SIGFPE);
    if (how_ == "exit") std::exit(0);
    throw std::runtime_error("a runtime error from " + stage_);
  }

  double speed_ = 1;
  std::string stage_ = "none", how_;
  std::int64_t at_ = 0;
  int step_ = -1;
  std::int64_t state_ = 0, computes_ = 0;
};

}  // namespace

BODYFIT_PLUGIN(FaultModel)
