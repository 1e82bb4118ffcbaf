#pragma once
// The velocity-model plugin interface.
//
// A plugin is a shared object exporting three C symbols (use BODYFIT_PLUGIN below):
//   uint32_t bodyfit_plugin_abi();            // kPluginAbi of the headers it was built with
//   bodyfit::VelocityModel* bodyfit_create(); // a new model, owned by the caller
//   void bodyfit_destroy(bodyfit::VelocityModel*);
// The loader checks the ABI before calling anything else. A model is created once per run,
// configured once from its TOML table, then compute() is called once per iteration of Algorithm 1
// on the current mesh T^n. The model object lives for the whole run and may keep state.
#include <bodyfit/mesh.hpp>

#include <Eigen/SparseCore>
#include <toml++/toml.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bodyfit {

inline constexpr std::uint32_t kPluginAbiMajor = 1;
inline constexpr std::uint32_t kPluginAbiMinor = 0;
inline constexpr std::uint32_t kPluginAbi = (kPluginAbiMajor << 16) | kPluginAbiMinor;

/// One parameter a model accepts, for `bodyfit plugins` and for error messages.
struct ParameterInfo {
  std::string name;
  std::string default_value;  ///< as written in TOML ("" when required)
  std::string description;    ///< with its unit
};

/// What compute() returns: a tangential vector field V at the vertices, or a normal speed v
/// (then V = v·n_Σ with n_Σ the extended unit conormal, a positive v growing G).
struct VelocityField {
  enum class Kind { Tangential, NormalSpeed };
  Kind kind = Kind::Tangential;
  VectorField vector;        ///< Kind::Tangential: one vector per vertex
  ScalarField normal_speed;  ///< Kind::NormalSpeed: one value per vertex
  /// Scalars the driver adds as columns of history.csv (same names every iteration).
  std::vector<std::pair<std::string, double>> metrics;
  /// Vertex fields the driver adds to this iteration's VTU.
  std::vector<std::pair<std::string, ScalarField>> point_fields;

  static VelocityField tangential(VectorField v) {
    VelocityField f;
    f.kind = Kind::Tangential;
    f.vector = std::move(v);
    return f;
  }
  static VelocityField normal(ScalarField v) {
    VelocityField f;
    f.kind = Kind::NormalSpeed;
    f.normal_speed = std::move(v);
    return f;
  }
};

/// Read-only view of the state at iteration n, with the helpers a model needs. Geometric helpers
/// are computed on first use and cached for the iteration.
class StepContext {
 public:
  struct Impl;
  explicit StepContext(std::unique_ptr<Impl> impl);
  ~StepContext();
  StepContext(const StepContext&) = delete;
  StepContext& operator=(const StepContext&) = delete;

  const SurfaceMesh& mesh() const;     ///< T^n: regions (f:region), interface (e:interface)
  const ScalarField& distance() const; ///< signed geodesic distance d_{G^n}, < 0 inside
  double time() const;                 ///< t^n
  double dt() const;                   ///< Δt of this step
  int iteration() const;               ///< n
  double mesh_size() const;            ///< mean edge length h of T^n
  const std::filesystem::path& output_dir() const;  ///< where a model may write its own files
  /// The surface's height function when it is a terrain (z coordinate), else empty.
  bool is_terrain() const;

  const std::vector<double>& face_areas() const;
  const VectorField& face_normals() const;
  const VectorField& vertex_normals() const;
  /// Unit conormal n_Σ = ∇_S d / |∇_S d| at the vertices, extended to the whole surface.
  const VectorField& conormal() const;
  /// Per-face and per-vertex tangential gradients of a P1 field.
  VectorField face_gradients(const ScalarField& u) const;
  VectorField vertex_gradients(const ScalarField& u) const;
  /// P1 mass and stiffness matrices on T^n (vertex-indexed).
  const Eigen::SparseMatrix<double>& mass_matrix() const;
  const Eigen::SparseMatrix<double>& stiffness_matrix() const;
  /// H¹ smoothing: u solving (M + ℓ²K) u = M f; for vector fields, component-wise then
  /// projected on the tangent planes. ℓ is a length (0 returns f).
  ScalarField smooth(const ScalarField& f, double length) const;
  VectorField smooth(const VectorField& f, double length) const;

 private:
  std::unique_ptr<Impl> impl_;
};

/// The state after the level-set step of iteration n (before remeshing): φ^{n+1} on T^n.
/// Models that track something through time (arrival times, objective histories) use it.
struct StepOutcome {
  const SurfaceMesh& mesh;          ///< T^n
  const ScalarField& distance;      ///< d_{G^n}
  const ScalarField& phi_next;      ///< φ^{n+1} at the vertices of T^n
  double time;                      ///< t^n
  double dt;
};

class VelocityModel {
 public:
  virtual ~VelocityModel() = default;
  virtual std::string_view name() const = 0;
  virtual std::string_view version() const { return "1.0"; }
  virtual std::string_view description() const { return ""; }
  virtual std::vector<ParameterInfo> parameters() const { return {}; }
  /// Validate and take the model's parameters (the [model] table of the case, without `name`).
  /// Throw InputError on an unknown key or a bad value, naming the key.
  virtual void configure(const toml::table& parameters) = 0;
  /// V^n on the current mesh.
  virtual VelocityField compute(const StepContext& context) = 0;
  /// Called after the advection of iteration n, before remeshing. Default: nothing.
  virtual void end_step(const StepOutcome&) {}
  /// Called once when the run ends (after the last iteration); may write files to output_dir.
  virtual void finish(const std::filesystem::path& /*output_dir*/) {}
};

}  // namespace bodyfit

#define BODYFIT_PLUGIN_EXPORT extern "C" __attribute__((visibility("default")))

/// Export the C entry points of a plugin whose model class is `ModelClass`.
#define BODYFIT_PLUGIN(ModelClass)                                                          \
  BODYFIT_PLUGIN_EXPORT std::uint32_t bodyfit_plugin_abi() { return ::bodyfit::kPluginAbi; } \
  BODYFIT_PLUGIN_EXPORT ::bodyfit::VelocityModel* bodyfit_create() { return new ModelClass(); } \
  BODYFIT_PLUGIN_EXPORT void bodyfit_destroy(::bodyfit::VelocityModel* model) { delete model; }
