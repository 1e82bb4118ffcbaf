#pragma once
// Where a model's declared grids and values go (ModelOutputs): as files in a run's directory, or
// kept in memory for an ensemble's reduction.
#include <bodyfit/app/dem.hpp>
#include <bodyfit/app/raster_io.hpp>
#include <bodyfit/model_outputs.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace bodyfit {

/// The NODATA value of the grids bodyfit writes.
inline constexpr double kGridNodata = -9999;

/// A grid output as a raster (NaN cells become kGridNodata) and its metadata (the declared unit).
HeightGrid to_raster(const GridField& grid);
RasterMetadata raster_metadata(const GridField& grid, const std::string& unit);
/// The declaration of the output `name` among `declared`; InputError when the model hands an
/// output it did not declare, or declared as another kind.
const OutputDecl& declared_output(const std::vector<OutputDecl>& declared, std::string_view name,
                                  OutputDecl::Kind kind, std::string_view model);

/// A run's outputs: each grid written at once as <directory>/<name>.<format> ("tif" or "asc"),
/// atomically; each value kept (values()).
class GridFiles final : public ModelOutputs {
 public:
  GridFiles(std::filesystem::path directory, std::string format, std::vector<OutputDecl> declared, std::string model);
  void grid(std::string_view name, const GridField& values) override;
  void value(std::string_view name, double value) override;
  const std::map<std::string, double, std::less<>>& values() const { return values_; }

 private:
  std::filesystem::path directory_;
  std::string format_;
  std::vector<OutputDecl> declared_;
  std::string model_;
  std::map<std::string, double, std::less<>> values_;
};

/// An ensemble member's outputs, kept for the reduction.
class KeptOutputs final : public ModelOutputs {
 public:
  KeptOutputs(std::vector<OutputDecl> declared, std::string model);
  void grid(std::string_view name, const GridField& values) override;
  void value(std::string_view name, double value) override;
  const std::map<std::string, GridField, std::less<>>& grids() const { return grids_; }
  const std::map<std::string, double, std::less<>>& values() const { return values_; }

 private:
  std::vector<OutputDecl> declared_;
  std::string model_;
  std::map<std::string, GridField, std::less<>> grids_;
  std::map<std::string, double, std::less<>> values_;
};

}  // namespace bodyfit
