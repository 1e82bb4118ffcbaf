#pragma once
// What a velocity model gives besides V: its outputs, declared once (VelocityModel::outputs) with
// their kind, unit and meaning, and how the members of an ensemble combine them; and where it hands
// them at the end of a run (VelocityModel::finish).
//
//   std::vector<OutputDecl> outputs() const override {
//     return {OutputDecl::grid("reach_time", "s", "time at which G first covered each cell")
//                 .combine(Combine::share("reach_probability", "probability that G covers a cell"))
//                 .combine(Combine::mean("reach_time_mean", "s", "mean time over the members that reach it")),
//             OutputDecl::metric("speed_max", "m/s", "largest speed on the front")};
//   }
//   void finish(const StepContext& final, ModelOutputs& out) override {
//     out.grid("reach_time", reach_grid_);
//   }
//
// A run writes each grid as <name>.tif (or .asc, [output] grid_format) in its output directory; an
// ensemble keeps each member's grids and values and combines them as declared.
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bodyfit {

/// Values on a regular grid in plan view: cell-centred, rows from north (row 0) to south, NaN where
/// there is no value.
struct GridField {
  std::size_t cols = 0, rows = 0;
  double x_origin = 0, y_origin = 0;  ///< lower-left corner of the lower-left cell
  double cell_size = 1;
  std::vector<double> values;         ///< rows × cols
  std::string crs;                    ///< coordinate system (WKT; "" when unknown)
  std::string description;            ///< what the values are, for the file's readers
  /// More KEY=value facts for the file's metadata (a start time…).
  std::vector<std::pair<std::string, std::string>> items;
};

/// How an ensemble combines one output over its members (OutputDecl::ensemble). `name` is the
/// combined file's stem; in `description`, "{members}" becomes the number of members combined and
/// "{percentile}" the percentile.
struct Combine {
  enum class Op {
    Share,        ///< the share of members with a value in a cell (a probability), 0 to 1
    Mean,         ///< the mean over the members with a value
    Percentiles,  ///< each of the ensemble's percentiles over the members with a value: <name><p>
  };
  Op op = Op::Mean;
  std::string name;
  std::string unit;
  std::string description;

  static Combine share(std::string name, std::string description);
  static Combine mean(std::string name, std::string unit, std::string description);
  static Combine percentiles(std::string name, std::string unit, std::string description);
};

/// One output of a model.
struct OutputDecl {
  enum class Kind {
    VertexField,  ///< a scalar or vector field of each state's VTU (VelocityField::point_fields)
    Metric,       ///< a column of history.csv (VelocityField::metrics, Review::metrics)
    Grid,         ///< a GridField given to ModelOutputs::grid at the end: <name>.tif or .asc
    Value,        ///< a number given to ModelOutputs::value at the end (a column of an ensemble's table)
    File,         ///< a file the model writes itself in the output directory (name: the file name)
  };
  Kind kind = Kind::Metric;
  std::string name;
  std::string unit;  ///< "" for none
  std::string description;
  std::vector<Combine> ensemble;  ///< Grid: how an ensemble combines the members' grids

  static OutputDecl vertex_field(std::string name, std::string unit, std::string description);
  static OutputDecl metric(std::string name, std::string unit, std::string description);
  static OutputDecl grid(std::string name, std::string unit, std::string description);
  static OutputDecl value(std::string name, std::string unit, std::string description);
  static OutputDecl file(std::string name, std::string description);
  OutputDecl combine(Combine how) const;
};
std::string_view to_string(OutputDecl::Kind kind);

/// Where a model hands its results at the end of a run (VelocityModel::finish). The driver's
/// implementation decides the format and place: a run writes files, an ensemble member keeps them
/// for the reduction. The model's own files (OutputDecl::Kind::File) go to StepContext::output_dir.
class ModelOutputs {
 public:
  virtual ~ModelOutputs() = default;
  /// A declared grid output.
  virtual void grid(std::string_view name, const GridField& values) = 0;
  /// A declared value.
  virtual void value(std::string_view name, double value) = 0;
};

}  // namespace bodyfit
