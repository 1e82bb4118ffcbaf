// A model's declared outputs as files, or kept for an ensemble (model_files.hpp).
#include <bodyfit/app/model_files.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <cmath>

namespace bodyfit {

HeightGrid to_raster(const GridField& grid) {
  HeightGrid raster;
  raster.cols = grid.cols, raster.rows = grid.rows;
  raster.x_origin = grid.x_origin, raster.y_origin = grid.y_origin;
  raster.cell_size = grid.cell_size;
  raster.nodata = kGridNodata;
  raster.heights = grid.values;
  raster.crs = grid.crs;
  return raster;
}

RasterMetadata raster_metadata(const GridField& grid, const std::string& unit) {
  return {.units = unit, .description = grid.description, .items = grid.items};
}

const OutputDecl& declared_output(const std::vector<OutputDecl>& declared, std::string_view name, OutputDecl::Kind kind,
                                  std::string_view model) {
  for (const OutputDecl& d : declared)
    if (d.name == name && d.kind == kind) return d;
  throw PluginError(fmt::format("model '{}' handed the {} output '{}', which it does not declare", model,
                                to_string(kind), name));
}

GridFiles::GridFiles(std::filesystem::path directory, std::string format, std::vector<OutputDecl> declared,
                     std::string model)
    : directory_(std::move(directory)), format_(std::move(format)), declared_(std::move(declared)),
      model_(std::move(model)) {}

void GridFiles::grid(std::string_view name, const GridField& values) {
  const OutputDecl& d = declared_output(declared_, name, OutputDecl::Kind::Grid, model_);
  if (directory_.empty()) return;
  write_raster(directory_ / fmt::format("{}.{}", name, format_), to_raster(values), raster_metadata(values, d.unit));
}

void GridFiles::value(std::string_view name, double value) {
  declared_output(declared_, name, OutputDecl::Kind::Value, model_);
  values_[std::string(name)] = value;
}

KeptOutputs::KeptOutputs(std::vector<OutputDecl> declared, std::string model)
    : declared_(std::move(declared)), model_(std::move(model)) {}

void KeptOutputs::grid(std::string_view name, const GridField& values) {
  declared_output(declared_, name, OutputDecl::Kind::Grid, model_);
  grids_[std::string(name)] = values;
}

void KeptOutputs::value(std::string_view name, double value) {
  declared_output(declared_, name, OutputDecl::Kind::Value, model_);
  values_[std::string(name)] = value;
}

}  // namespace bodyfit
