#pragma once
// PythonModel: a velocity model written in Python, run by the engine as any plugin's model.
//
// The model is an object with a compute(step) method and optional attributes and methods
// (docs/guide/python.md): name, version, description, parameters, outputs, may_reject,
// freeze_velocity, configure(params), end_step(outcome), review(candidate, attempt),
// save_state(), load_state(state), finish(step). Every call takes the GIL; a Python exception
// becomes a PluginError (exit 4) carrying its traceback. The engine's arrays reach Python as
// read-only numpy views (Step), valid during the call that received them.
//
// Two ways in: an object given to bodyfit.run (PythonModel(instance)), or a case's
// `[model] name = "python"` with `module` and `class` (PythonModel::from_case(): configure()
// imports the module and makes the object, then reads the class's parameters).
#include <bodyfit/velocity_model.hpp>

#include <pybind11/pybind11.h>

#include <string>

namespace bodyfit::python {

/// Bind the types a model's methods receive (Step) into `module`; module-local, so the bodyfit
/// module and the plugin's embedded interpreter each keep their own.
void bind_model_types(pybind11::module_& module);

class PythonModel final : public VelocityModel {
 public:
  /// A model object made by the caller; `origin` names it in messages.
  PythonModel(pybind11::object instance, std::string origin);
  /// The `python` model of a case: `module` and `class` are read by configure().
  static std::unique_ptr<PythonModel> from_case();
  ~PythonModel() override;

  std::string_view name() const override { return name_; }
  std::string_view version() const override { return version_; }
  std::string_view description() const override { return description_; }
  std::vector<ParameterDecl> parameters() const override;
  std::vector<OutputDecl> outputs() const override { return outputs_; }
  void configure(Parameters& parameters) override;
  ModelNeeds needs() const override { return needs_; }
  VelocityField compute(const StepContext& context) override;
  void end_step(const StepOutcome& outcome) override;
  Review review(const StepContext& candidate, int attempt) override;
  void save_state(ModelState& state) const override;
  void load_state(const ModelState& state) override;
  void finish(const StepContext& final_state, ModelOutputs& outputs) override;

 private:
  PythonModel() = default;
  /// Read the object's attributes (name, declarations, needs).
  void adopt(pybind11::object instance);
  bool has_method(const char* method) const;

  pybind11::object instance_;
  std::string origin_ = "python";
  bool from_case_ = false;
  std::string name_ = "python", version_ = "1.0", description_;
  std::vector<ParameterDecl> declared_;  ///< the object's parameters
  std::vector<OutputDecl> outputs_;
  ModelNeeds needs_;
  std::uint32_t state_version_ = 0;
};

}  // namespace bodyfit::python
