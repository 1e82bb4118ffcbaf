// Digital elevation models: ESRI ASCII grids (read/write) and GeoTIFF (read, through GDAL when
// bodyfit was built with it), bilinear sampling. NODATA cells are filled with the value of the
// nearest valid cell (breadth-first over the 8-neighbourhood) and a warning says how many; a raster
// without any valid cell is an error.
#include <bodyfit/generators.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

// GDAL's include directory is on the path only when bodyfit_core links GDAL (cmake/BodyfitDependencies).
#if __has_include(<gdal.h>)
#define BODYFIT_DEM_HAVE_GDAL 1
#include <cpl_error.h>
#include <gdal.h>
#endif

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

namespace bodyfit {
namespace {

bool is_nodata(double value, double nodata) { return std::isnan(value) || value == nodata; }

// Replace NODATA cells by their nearest valid cell (multi-source BFS, 8-neighbourhood).
void fill_nodata(HeightGrid& grid, const std::filesystem::path& file) {
  const std::size_t n = grid.heights.size();
  std::vector<char> valid(n, 0);
  std::vector<std::size_t> queue;
  for (std::size_t i = 0; i < n; ++i)
    if (!is_nodata(grid.heights[i], grid.nodata)) valid[i] = 1, queue.push_back(i);
  if (queue.size() == n) return;
  if (queue.empty()) throw file_error(file, "every cell is NODATA");
  const std::size_t missing = n - queue.size();
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t r = queue[head] / grid.cols, c = queue[head] % grid.cols;
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const long rr = long(r) + dr, cc = long(c) + dc;
        if (rr < 0 || cc < 0 || rr >= long(grid.rows) || cc >= long(grid.cols)) continue;
        const std::size_t k = std::size_t(rr) * grid.cols + std::size_t(cc);
        if (valid[k]) continue;
        valid[k] = 1;
        grid.heights[k] = grid.heights[queue[head]];
        queue.push_back(k);
      }
  }
  spdlog::warn("{}: {} NODATA cell(s) of {} filled with the nearest valid height", file.string(), missing, n);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

std::optional<double> parse_number(const std::string& token) {
  double value = 0;
  const char* begin = token.data();
  const char* end = begin + token.size();
  if (begin != end && *begin == '+') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

double HeightGrid::sample(double x, double y) const {
  // Continuous cell coordinates: cell centres at integers, u eastward, v northward from the south row.
  const double u = std::clamp((x - x_origin) / cell_size - 0.5, 0.0, double(cols - 1));
  const double v = std::clamp((y - y_origin) / cell_size - 0.5, 0.0, double(rows - 1));
  const std::size_t c0 = std::min(std::size_t(u), cols > 1 ? cols - 2 : 0);
  const std::size_t s0 = std::min(std::size_t(v), rows > 1 ? rows - 2 : 0);
  const std::size_t c1 = std::min(c0 + 1, cols - 1), s1 = std::min(s0 + 1, rows - 1);
  const double fu = u - double(c0), fv = v - double(s0);
  auto south = [&](std::size_t s, std::size_t c) { return at(rows - 1 - s, c); };
  const double lower_row = (1 - fu) * south(s0, c0) + fu * south(s0, c1);
  const double upper_row = (1 - fu) * south(s1, c0) + fu * south(s1, c1);
  return (1 - fv) * lower_row + fv * upper_row;
}

HeightGrid read_esri_ascii(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw file_error(file, "cannot open for reading");
  HeightGrid grid;
  std::map<std::string, double> header;
  std::map<std::string, long> header_line;
  std::string line;
  long line_no = 0;
  std::vector<std::string> first_values;  // tokens of the first data line, read while looking for the header
  long first_data_line = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;  // blank line
    if (!std::isalpha(static_cast<unsigned char>(key[0]))) {
      first_data_line = line_no;
      first_values.push_back(key);
      for (std::string w; words >> w;) first_values.push_back(w);
      break;
    }
    key = lower(key);
    static const std::array<const char*, 8> known = {"ncols",     "nrows",    "xllcorner", "xllcenter",
                                                     "yllcorner", "yllcenter", "cellsize", "nodata_value"};
    if (key == "dx" || key == "dy")
      throw file_error(file, line_no, "non-square cells (dx/dy) are not supported: resample to one cellsize");
    if (std::find(known.begin(), known.end(), key) == known.end())
      throw file_error(file, line_no, fmt::format("unknown header key '{}'", key));
    std::string value_text, extra;
    if (!(words >> value_text)) throw file_error(file, line_no, fmt::format("header key '{}' has no value", key));
    auto value = parse_number(value_text);
    if (!value) throw file_error(file, line_no, fmt::format("'{}' is not a number (header key '{}')", value_text, key));
    if (words >> extra) throw file_error(file, line_no, fmt::format("unexpected '{}' after header key '{}'", extra, key));
    if (header.count(key)) throw file_error(file, line_no, fmt::format("header key '{}' given twice", key));
    header[key] = *value;
    header_line[key] = line_no;
  }
  const long where = first_data_line ? first_data_line : line_no + 1;
  for (const char* key : {"ncols", "nrows", "cellsize"})
    if (!header.count(key)) throw file_error(file, where, fmt::format("missing header key '{}'", key));
  auto count_of = [&](const char* key) {
    double v = header[key];
    if (v < 1 || v != std::floor(v) || v > 1e9)
      throw file_error(file, header_line[key], fmt::format("'{}' must be a positive integer", key));
    return std::size_t(v);
  };
  grid.cols = count_of("ncols");
  grid.rows = count_of("nrows");
  grid.cell_size = header["cellsize"];
  if (!(grid.cell_size > 0)) throw file_error(file, header_line["cellsize"], "'cellsize' must be positive");
  auto origin = [&](const char* corner, const char* center, const char* axis) {
    if (header.count(corner) && header.count(center))
      throw file_error(file, header_line[center], fmt::format("both '{}' and '{}' given", corner, center));
    if (header.count(corner)) return header[corner];
    if (header.count(center)) return header[center] - grid.cell_size / 2;
    throw file_error(file, where, fmt::format("missing header key '{}' (or '{}') for {}", corner, center, axis));
  };
  grid.x_origin = origin("xllcorner", "xllcenter", "x");
  grid.y_origin = origin("yllcorner", "yllcenter", "y");
  if (header.count("nodata_value")) grid.nodata = header["nodata_value"];

  const std::size_t expected = grid.rows * grid.cols;
  if (double(grid.rows) * double(grid.cols) > 4e8) throw file_error(file, "raster too large");
  // Room for the values the file can hold (each takes two bytes or more), not for what its header
  // claims: a 20000 x 20000 header on a few bytes reserved 3.2 GB (found by fuzz_esri_grid).
  std::error_code size_error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(file, size_error);
  grid.heights.reserve(size_error ? 0 : std::size_t(std::min<std::uintmax_t>(expected, file_bytes / 2 + 1)));
  auto take = [&](const std::string& token, long at_line) {
    auto value = parse_number(token);
    if (!value) throw file_error(file, at_line, fmt::format("'{}' is not a number", token));
    if (grid.heights.size() == expected)
      throw file_error(file, at_line, fmt::format("too many values: expected {} rows × {} columns", grid.rows, grid.cols));
    grid.heights.push_back(*value);
  };
  for (const auto& token : first_values) take(token, first_data_line);
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream words(line);
    for (std::string w; words >> w;) take(w, line_no);
  }
  if (grid.heights.size() < expected)
    throw file_error(file, line_no, fmt::format("truncated: expected {} values ({} rows × {} columns), found {}",
                                                expected, grid.rows, grid.cols, grid.heights.size()));
  fill_nodata(grid, file);
  return grid;
}

void write_esri_ascii(const std::filesystem::path& file, const HeightGrid& grid) {
  if (grid.cols == 0 || grid.rows == 0 || grid.heights.size() != grid.rows * grid.cols)
    throw InputError(fmt::format("{}: cannot write an empty or inconsistent height grid", file.string()));
  write_atomically(file, [&](std::ostream& out) {
    out << fmt::format("ncols {}\nnrows {}\nxllcorner {}\nyllcorner {}\ncellsize {}\nNODATA_value {}\n", grid.cols,
                       grid.rows, grid.x_origin, grid.y_origin, grid.cell_size, grid.nodata);
    std::string row;
    for (std::size_t r = 0; r < grid.rows; ++r) {
      row.clear();
      for (std::size_t c = 0; c < grid.cols; ++c) {
        if (c) row += ' ';
        row += fmt::format("{}", grid.at(r, c));  // shortest representation that reads back exactly
      }
      row += '\n';
      out << row;
    }
  });
}

namespace {

[[noreturn]] void no_gdal(const std::filesystem::path& file) {
  throw file_error(file, "cannot read GeoTIFF: bodyfit was built without GDAL (install libgdal-dev and "
                         "reconfigure, or convert the DEM to an ESRI ASCII grid .asc)");
}

#if BODYFIT_DEM_HAVE_GDAL
// inline: not emitted (so GDAL is not needed at link time) when config::have_gdal discards the call.
inline HeightGrid read_geotiff_with_gdal(const std::filesystem::path& file) {
  GDALAllRegister();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  GDALDatasetH dataset = GDALOpen(file.string().c_str(), GA_ReadOnly);
  CPLPopErrorHandler();
  if (!dataset) throw file_error(file, fmt::format("cannot open as a raster (GDAL: {})", CPLGetLastErrorMsg()));
  struct Closer {
    GDALDatasetH d;
    ~Closer() { GDALClose(d); }
  } closer{dataset};
  if (GDALGetRasterCount(dataset) < 1) throw file_error(file, "the raster has no band");
  double gt[6];
  if (GDALGetGeoTransform(dataset, gt) != CE_None) throw file_error(file, "the raster has no georeferencing (geotransform)");
  if (gt[2] != 0 || gt[4] != 0) throw file_error(file, "rotated rasters are not supported");
  if (std::abs(std::abs(gt[1]) - std::abs(gt[5])) > 1e-9 * std::abs(gt[1]) || gt[1] <= 0)
    throw file_error(file, fmt::format("non-square or mirrored cells ({} × {}) are not supported", gt[1], gt[5]));
  HeightGrid grid;
  grid.cols = std::size_t(GDALGetRasterXSize(dataset));
  grid.rows = std::size_t(GDALGetRasterYSize(dataset));
  grid.cell_size = gt[1];
  grid.x_origin = gt[0];
  grid.y_origin = gt[5] < 0 ? gt[3] + double(grid.rows) * gt[5] : gt[3];
  GDALRasterBandH band = GDALGetRasterBand(dataset, 1);
  int has_nodata = 0;
  double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  if (has_nodata) grid.nodata = nodata;
  grid.heights.resize(grid.rows * grid.cols);
  if (GDALRasterIO(band, GF_Read, 0, 0, int(grid.cols), int(grid.rows), grid.heights.data(), int(grid.cols),
                   int(grid.rows), GDT_Float64, 0, 0) != CE_None)
    throw file_error(file, fmt::format("cannot read band 1 (GDAL: {})", CPLGetLastErrorMsg()));
  if (gt[5] > 0)  // south-up raster: store north first like an ESRI grid
    for (std::size_t r = 0; r < grid.rows / 2; ++r)
      std::swap_ranges(grid.heights.begin() + long(r * grid.cols), grid.heights.begin() + long((r + 1) * grid.cols),
                       grid.heights.begin() + long((grid.rows - 1 - r) * grid.cols));
  fill_nodata(grid, file);
  return grid;
}
#endif

}  // namespace

HeightGrid read_geotiff(const std::filesystem::path& file) {
#if BODYFIT_DEM_HAVE_GDAL
  if constexpr (config::have_gdal) return read_geotiff_with_gdal(file);
#endif
  no_gdal(file);
}

HeightGrid read_dem(const std::filesystem::path& file) {
  const std::string ext = lower(file.extension().string());
  if (ext == ".asc") return read_esri_ascii(file);
  if (ext == ".tif" || ext == ".tiff") return read_geotiff(file);
  throw file_error(file, "unknown DEM format: expected .asc (ESRI ASCII grid) or .tif/.tiff (GeoTIFF)");
}

}  // namespace bodyfit
