// Digital elevation models: ESRI ASCII grids (read/write) and GeoTIFF (read, through the GDAL module when
// bodyfit was built with it), bilinear sampling over the valid cells, the nearest-valid fill. NODATA
// cells are read as they are (no terrain, no fuel: the users of the raster decide); a raster without
// any valid cell is an error.
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>

#include "gis_module.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>


#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

namespace bodyfit {
namespace {

bool is_nodata(double value, double nodata) { return std::isnan(value) || value == nodata; }

void require_some_data(const HeightGrid& grid, const std::filesystem::path& file) {
  if (count_nodata(grid) == grid.heights.size()) throw file_error(file, "every cell is NODATA");
}

// Heights beyond this are not terrain (the Earth's radius is 6.4e6 m; in feet, 2.1e7): a NODATA
// marker the header does not declare, or a damaged cell. A mesh built on one would be refused
// later anyway, by whichever stage first squares its size.
constexpr double kMaxHeight = 1e8;

void check_heights(const HeightGrid& grid, const std::filesystem::path& file) {
  for (std::size_t i = 0; i < grid.heights.size(); ++i)
    if (!is_nodata(grid.heights[i], grid.nodata) && !(std::abs(grid.heights[i]) <= kMaxHeight))
      throw file_error(file, fmt::format("the height {} of the cell at row {}, column {} is beyond ±{:.0e}: not a "
                                         "terrain height (a NODATA value the header does not declare?)",
                                         grid.heights[i], i / grid.cols + 1, i % grid.cols + 1, kMaxHeight));
}

// NODATA markers of common formats: never heights. A DEM whose header does not declare its marker
// would otherwise carry pits 10 km deep (the fire then ran down them without a word).
constexpr double kMarkers[] = {-9999.0, -99999.0, -32768.0, -32767.0, -3.4028234663852886e38};

/// A warning about a raster, said once per process: a run reads its DEM more than once (the terrain,
/// then its coordinate system; each ensemble member), and the same cells need naming only once.
template <class... Args>
void warn_once(fmt::format_string<Args...> format, Args&&... args) {
  static std::mutex mutex;
  static std::set<std::string> said;
  std::string text = fmt::format(format, std::forward<Args>(args)...);
  const std::lock_guard lock(mutex);
  if (said.insert(text).second) spdlog::warn("{}", text);
}

/// An undeclared marker becomes NODATA; a cell standing alone far off its neighbours (a spike or a
/// pit: a damaged cell, a tower in a surface model) takes their median. Both said, naming cells.
void screen_heights(HeightGrid& grid, const std::filesystem::path& file) {
  const std::size_t rows = grid.rows, cols = grid.cols, n = grid.heights.size();
  std::vector<std::string> markers;
  std::size_t marked = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double& z = grid.heights[i];
    if (is_nodata(z, grid.nodata) || std::find(std::begin(kMarkers), std::end(kMarkers), z) == std::end(kMarkers)) continue;
    if (markers.size() < 5) markers.push_back(fmt::format("row {}, column {}: {}", i / cols + 1, i % cols + 1, z));
    z = std::numeric_limits<double>::quiet_NaN();
    ++marked;
  }
  if (marked)
    warn_once("{}: {} cell(s) hold a NODATA marker the header does not declare (its NODATA_value is {}), taken as "
                 "NODATA: {}{}",
                 file.string(), marked, grid.nodata, fmt::join(markers, "; "), marked > markers.size() ? "; ..." : "");
  require_some_data(grid, file);
  check_heights(grid, file);

  // d: each cell's distance to the median of its valid neighbours (cells with fewer than three are
  // not judged). A spike is far off beyond the grid's own roughness and beyond its neighbours'.
  std::vector<double> median(n, 0.0), off(n, 0.0);
  std::vector<char> judged(n, 0);
  std::vector<double> around;
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < cols; ++c) {
      const std::size_t i = r * cols + c;
      if (!grid.valid(r, c)) continue;
      around.clear();
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const long rr = long(r) + dr, cc = long(c) + dc;
          if ((dr || dc) && rr >= 0 && cc >= 0 && rr < long(rows) && cc < long(cols) && grid.valid(std::size_t(rr), std::size_t(cc)))
            around.push_back(grid.at(std::size_t(rr), std::size_t(cc)));
        }
      if (around.size() < 3) continue;
      std::nth_element(around.begin(), around.begin() + std::ptrdiff_t(around.size() / 2), around.end());
      median[i] = around[around.size() / 2];
      off[i] = std::abs(grid.heights[i] - median[i]);
      judged[i] = 1;
    }
  std::vector<double> offs;
  for (std::size_t i = 0; i < n; ++i)
    if (judged[i]) offs.push_back(off[i]);
  if (offs.empty()) return;
  std::nth_element(offs.begin(), offs.begin() + std::ptrdiff_t(offs.size() / 2), offs.end());
  const double roughness = 1.4826 * offs[offs.size() / 2];
  const double threshold = std::max(30 * roughness, 3 * grid.cell_size);
  std::vector<std::string> spikes;
  std::size_t despiked = 0;
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t c = 0; c < cols; ++c) {
      const std::size_t i = r * cols + c;
      if (!judged[i] || !(off[i] > threshold)) continue;
      double neighbours = 0;  // the largest d around: a cliff's cells are all far off, a spike alone
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const long rr = long(r) + dr, cc = long(c) + dc;
          if ((dr || dc) && rr >= 0 && cc >= 0 && rr < long(rows) && cc < long(cols))
            neighbours = std::max(neighbours, off[std::size_t(rr) * cols + std::size_t(cc)]);
        }
      if (!(off[i] > 5 * neighbours)) continue;
      if (spikes.size() < 5)
        spikes.push_back(fmt::format("row {}, column {}: {} -> {}", r + 1, c + 1, grid.heights[i], median[i]));
      grid.heights[i] = median[i];
      ++despiked;
    }
  if (despiked)
    warn_once("{}: {} cell(s) stand alone {:.3g} or more off the median of their neighbours (more than 30 times "
                 "the grid's roughness and 3 cells' size, and 5 times any neighbour's), taken as damaged and given "
                 "that median: {}{}",
                 file.string(), despiked, threshold, fmt::join(spikes, "; "), despiked > spikes.size() ? "; ..." : "");
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

bool same_frame(const HeightGrid& a, const HeightGrid& b) {
  return a.cols == b.cols && a.rows == b.rows && a.x_origin == b.x_origin && a.y_origin == b.y_origin &&
         a.cell_size == b.cell_size;
}

bool HeightGrid::valid(std::size_t row, std::size_t col) const { return !is_nodata(at(row, col), nodata); }

std::size_t count_nodata(const HeightGrid& grid) {
  return std::size_t(std::count_if(grid.heights.begin(), grid.heights.end(),
                                   [&](double value) { return is_nodata(value, grid.nodata); }));
}

std::size_t fill_nodata(HeightGrid& grid) {
  const std::size_t n = grid.heights.size();
  std::vector<char> valid(n, 0);
  std::vector<std::size_t> queue;
  for (std::size_t i = 0; i < n; ++i)
    if (!is_nodata(grid.heights[i], grid.nodata)) valid[i] = 1, queue.push_back(i);
  if (queue.size() == n || queue.empty()) return 0;
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
  return missing;
}

double HeightGrid::sample(double x, double y) const {
  // Continuous cell coordinates: cell centres at integers, u eastward, v northward from the south row.
  const double u = std::clamp((x - x_origin) / cell_size - 0.5, 0.0, double(cols - 1));
  const double v = std::clamp((y - y_origin) / cell_size - 0.5, 0.0, double(rows - 1));
  const std::size_t c0 = std::min(std::size_t(u), cols > 1 ? cols - 2 : 0);
  const std::size_t s0 = std::min(std::size_t(v), rows > 1 ? rows - 2 : 0);
  const std::size_t c1 = std::min(c0 + 1, cols - 1), s1 = std::min(s0 + 1, rows - 1);
  const double fu = u - double(c0), fv = v - double(s0);
  auto south = [&](std::size_t s, std::size_t c) { return at(rows - 1 - s, c); };
  auto valid_south = [&](std::size_t s, std::size_t c) { return valid(rows - 1 - s, c); };
  if (valid_south(s0, c0) && valid_south(s0, c1) && valid_south(s1, c0) && valid_south(s1, c1)) {
    const double lower_row = (1 - fu) * south(s0, c0) + fu * south(s0, c1);
    const double upper_row = (1 - fu) * south(s1, c0) + fu * south(s1, c1);
    return (1 - fv) * lower_row + fv * upper_row;
  }
  // Next to NODATA: the valid corners only, their weights renormalised (or, when those weights are
  // all zero, their plain mean).
  const std::array<std::array<std::size_t, 2>, 4> corner{{{s0, c0}, {s0, c1}, {s1, c0}, {s1, c1}}};
  const std::array<double, 4> weight{(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv};
  double sum = 0, weights = 0, plain_sum = 0;
  int count = 0;
  for (int k = 0; k < 4; ++k) {
    const auto [s, c] = corner[std::size_t(k)];
    if (!valid_south(s, c)) continue;
    sum += weight[std::size_t(k)] * south(s, c);
    weights += weight[std::size_t(k)];
    plain_sum += south(s, c);
    ++count;
  }
  if (weights > 0) return sum / weights;
  return count ? plain_sum / count : std::numeric_limits<double>::quiet_NaN();
}

namespace {

std::filesystem::path prj_beside(const std::filesystem::path& file) {
  std::filesystem::path prj = file;
  return prj.replace_extension(".prj");
}

/// The coordinate system of an ESRI grid: the text of the .prj beside it ("" when there is none).
std::string read_prj(const std::filesystem::path& file) {
  const auto prj = prj_beside(file);
  std::error_code ec;
  if (!std::filesystem::exists(prj, ec)) return {};
  std::ifstream in(prj);
  if (!in) throw file_error(prj, "cannot open for reading");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  if (text.empty()) throw file_error(prj, "empty coordinate system file (expected WKT, e.g. from gdalsrsinfo -o wkt_esri)");
  return text;
}

/// The WGS 84 / UTM zone of a raster's centre, its coordinates taken as degrees of longitude and latitude.
struct UtmZone {
  int zone = 0;
  bool north = true;
  int epsg() const { return (north ? 32600 : 32700) + zone; }
};

UtmZone utm_zone_of(const HeightGrid& grid) {
  const double lon = grid.x_origin + 0.5 * grid.cell_size * double(grid.cols);
  const double lat = grid.y_origin + 0.5 * grid.cell_size * double(grid.rows);
  return {std::clamp(int(std::floor((lon + 180) / 6)) + 1, 1, 60), lat >= 0};
}

/// Degrees are not metres. A geographic raster is refused, with the UTM zone of its centre to
/// project it to; a projected one in other units than metres too. Without a coordinate system,
/// coordinates that look like degrees get a warning.
void require_metres(const HeightGrid& grid, const std::filesystem::path& file) {
  const double west = grid.x_origin, south = grid.y_origin;
  const double east = west + grid.cell_size * double(grid.cols), north = south + grid.cell_size * double(grid.rows);
  const UtmZone zone = utm_zone_of(grid);
  const std::string projection =
      fmt::format("gdalwarp -t_srs EPSG:{} {} projected.tif` (WGS 84 / UTM zone {}{}, that of its centre)", zone.epsg(),
                  file.string(), zone.zone, zone.north ? 'N' : 'S');
  if (grid.crs.empty()) {
    if (grid.cell_size < 0.01 && west >= -180 && east <= 180 && south >= -90 && north <= 90)
      warn_once("{}: no coordinate system (no .prj) and cells of {} m: if these are degrees, project the raster "
                   "first, e.g. `{}",
                   file.string(), grid.cell_size, projection);
    return;
  }
  const gis::Api& gis = gis::module_for(file);
  gis::CrsInfo info;
  std::string error;
  if (!gis.describe_crs(grid.crs, info, error)) throw file_error(file, error);
  if (info.geographic)
    throw file_error(file, fmt::format("its coordinate system '{}' is geographic (degrees of longitude and latitude), "
                                       "and bodyfit works in metres: project the raster first, e.g. `{}, or let "
                                       "bodyfit do it ([surface] reproject = \"utm\", bodyfit mesh terrain "
                                       "--reproject utm)",
                                       info.name, projection));
  if (std::abs(info.metres_per_unit - 1) > 1e-9)
    throw file_error(file, fmt::format("its coordinate system '{}' measures in units of {} m, and bodyfit works in "
                                       "metres: reproject it to a metric system (gdalwarp -t_srs)",
                                       info.name, info.metres_per_unit));
}

/// A geographic raster warped to the UTM zone of its centre, or to options.target_crs (through the
/// GDAL module), said in the log; any other raster is returned as it is.
HeightGrid reproject_to_utm(HeightGrid grid, const std::filesystem::path& file, const DemReadOptions& options) {
  if (grid.crs.empty()) return grid;  // nothing to reproject from: require_metres warns if it looks like degrees
  const gis::Api& gis = gis::module_for(file);
  gis::CrsInfo from;
  std::string error;
  if (!gis.describe_crs(grid.crs, from, error)) throw file_error(file, error);
  if (!from.geographic) return grid;
  int epsg = utm_zone_of(grid).epsg();
  if (!options.target_crs.empty()) {
    gis::CrsInfo target;
    if (!gis.describe_crs(options.target_crs, target, error)) throw file_error(file, error);
    if (target.epsg == 0 || target.geographic)
      throw file_error(file, fmt::format("cannot reproject it to '{}', a system without an EPSG code or in degrees",
                                         target.name));
    epsg = target.epsg;
  }
  HeightGrid warped;
  if (!gis.warp_raster(grid, epsg, 0, options.resampling, warped, error))
    throw file_error(file, fmt::format("cannot reproject it to EPSG:{}: {}", epsg, error));
  gis::CrsInfo to;
  if (!gis.describe_crs(warped.crs, to, error)) throw file_error(file, error);
  spdlog::info("{}: reprojected from {} to {}, {} m cells ({} × {}, {}, NODATA kept)", file.string(), from.name,
               to.name, warped.cell_size, warped.cols, warped.rows,
               options.resampling == Resampling::nearest ? "nearest cell" : "bilinear");
  return warped;
}

/// The raster as the file holds it, with a terrain's checks.
// A landscape's band as it is (NODATA kept), its values scaled to SI by the unit its header names.
HeightGrid read_landscape_band_as_is(const std::filesystem::path& file, LandscapeBand band) {
  static const std::map<std::string, double> lengths = {
      {"Meters", 1.0}, {"Feet", 0.3048}, {"Meters x 10", 0.1}, {"Feet x 10", 0.03048}};
  static const std::map<std::string, double> densities = {
      {"kg/m^3", 1.0}, {"lb/ft^3", 16.018463}, {"kg/m^3 x 100", 0.01}, {"lb/ft^3 x 1000", 0.016018463}};
  static const std::map<std::string, double> covers = {{"Percent", 1.0}};
  const gis::Api& gis = gis::module_for(file);
  HeightGrid grid;
  std::string unit, error;
  if (!gis.read_raster_band(file, int(band), grid, unit, error)) throw file_error(file, error);
  const std::map<std::string, double>* units = nullptr;
  switch (band) {
    case LandscapeBand::elevation:
    case LandscapeBand::canopy_height:
    case LandscapeBand::canopy_base_height: units = &lengths; break;
    case LandscapeBand::canopy_bulk_density: units = &densities; break;
    case LandscapeBand::canopy_cover: units = &covers; break;
    default: break;
  }
  if (units) {
    const auto found = units->find(unit);
    if (found == units->end())
      throw file_error(file, fmt::format("band {}: unit '{}' is not one bodyfit converts (expected one of a FARSITE "
                                         "landscape's)",
                                         int(band), unit));
    for (double& v : grid.heights)
      if (!is_nodata(v, grid.nodata)) v *= found->second;
  }
  require_some_data(grid, file);
  return grid;
}

HeightGrid read_dem_as_is(const std::filesystem::path& file) {
  const std::string ext = lower(file.extension().string());
  if (ext == ".asc") return read_esri_ascii(file);
  if (ext == ".tif" || ext == ".tiff") return read_geotiff(file);
  if (ext == ".lcp") {
    HeightGrid grid = read_landscape_band_as_is(file, LandscapeBand::elevation);
    screen_heights(grid, file);
    return grid;
  }
  throw file_error(file, "unknown DEM format: expected .asc (ESRI ASCII grid), .tif/.tiff (GeoTIFF) or .lcp (a "
                         "FARSITE landscape)");
}

}  // namespace

HeightGrid read_esri_ascii_values(const std::filesystem::path& file) {
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
  // Each value takes two bytes at least ("0 "): a header that declares more than the file can hold
  // is refused before memory is reserved for it.
  std::error_code size_error;
  const auto bytes = std::filesystem::file_size(file, size_error);
  if (!size_error && double(expected) > double(bytes) / 2 + 1)
    throw file_error(file, fmt::format("the header declares {} rows × {} columns, more values than the file's {} "
                                       "bytes can hold (truncated?)",
                                       grid.rows, grid.cols, bytes));
  grid.heights.reserve(expected);
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
  grid.crs = read_prj(file);
  return grid;
}

HeightGrid read_esri_ascii(const std::filesystem::path& file) {
  HeightGrid grid = read_esri_ascii_values(file);
  require_some_data(grid, file);
  screen_heights(grid, file);
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
  if (!grid.crs.empty()) write_atomically(prj_beside(file), [&](std::ostream& out) { out << grid.crs << '\n'; });
}

HeightGrid read_geotiff(const std::filesystem::path& file) {
  const gis::Api& gis = gis::module_for(file);
  HeightGrid grid;
  std::string error;
  if (!gis.read_raster(file, grid, error)) throw file_error(file, error);
  require_some_data(grid, file);
  screen_heights(grid, file);
  return grid;
}

HeightGrid read_dem(const std::filesystem::path& file, const DemReadOptions& options) {
  HeightGrid grid = read_dem_as_is(file);
  if (options.reproject == Reprojection::utm) grid = reproject_to_utm(std::move(grid), file, options);
  require_metres(grid, file);
  return grid;
}

HeightGrid read_raster(const std::filesystem::path& file, const DemReadOptions& options) {
  const std::string ext = lower(file.extension().string());
  HeightGrid grid;
  if (ext == ".asc") {
    grid = read_esri_ascii_values(file);
  } else if (ext == ".tif" || ext == ".tiff") {
    std::string error;
    if (!gis::module_for(file).read_raster(file, grid, error)) throw file_error(file, error);
  } else {
    throw file_error(file, "unknown raster format: expected .asc (ESRI ASCII grid) or .tif/.tiff (GeoTIFF)");
  }
  require_some_data(grid, file);
  if (options.reproject == Reprojection::utm) grid = reproject_to_utm(std::move(grid), file, options);
  require_metres(grid, file);
  return grid;
}

HeightGrid read_landscape_band(const std::filesystem::path& file, LandscapeBand band, const DemReadOptions& options) {
  HeightGrid grid = read_landscape_band_as_is(file, band);
  if (options.reproject == Reprojection::utm) grid = reproject_to_utm(std::move(grid), file, options);
  require_metres(grid, file);
  return grid;
}

DemCoordinates dem_coordinates(const std::filesystem::path& file, const DemReadOptions& options) {
  HeightGrid grid = read_dem_as_is(file);
  DemCoordinates coordinates{.crs = grid.crs};
  if (options.reproject == Reprojection::utm) {
    const std::string own = grid.crs;
    grid = reproject_to_utm(std::move(grid), file, options);
    if (grid.crs != own) coordinates = {.crs = grid.crs, .reprojected_from = own};
  }
  require_metres(grid, file);
  return coordinates;
}

void require_same_crs(const HeightGrid& a, const std::filesystem::path& file_a, const HeightGrid& b,
                      const std::filesystem::path& file_b) {
  if (a.crs.empty() || b.crs.empty() || a.crs == b.crs) return;
  const gis::Api& gis = gis::module_for(file_a);
  if (gis.same_crs(a.crs, b.crs)) return;
  gis::CrsInfo info_a, info_b;
  std::string error;
  gis.describe_crs(a.crs, info_a, error);
  gis.describe_crs(b.crs, info_b, error);
  throw InputError(fmt::format("{} and {} have different coordinate systems ('{}' and '{}'): reproject one onto the "
                               "other (gdalwarp -t_srs)",
                               file_a.string(), file_b.string(), info_a.name, info_b.name));
}

}  // namespace bodyfit
