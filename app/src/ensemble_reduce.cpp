// The reduction of an ensemble: the members' files, read in index order, into rasters and the
// member table (ensemble.hpp).
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/app/config.hpp>
#include <bodyfit/app/ensemble.hpp>
#include <bodyfit/app/model_files.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/render.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace bodyfit {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A member's grid as written: NODATA cells become NaN (read_dem would fill them).
HeightGrid read_member_grid(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw file_error(file, "cannot open the member's grid");
  HeightGrid grid;
  long line = 0;
  auto header = [&](const char* expected) {
    std::string key;
    std::string value;
    ++line;
    if (!(in >> key >> value)) throw file_error(file, line, fmt::format("expected '{} <value>'", expected));
    std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (key != expected) throw file_error(file, line, fmt::format("expected '{}', found '{}'", expected, key));
    double v = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || end != value.data() + value.size())
      throw file_error(file, line, fmt::format("{}: expected a number, found '{}'", expected, value));
    return v;
  };
  grid.cols = std::size_t(header("ncols"));
  grid.rows = std::size_t(header("nrows"));
  grid.x_origin = header("xllcorner");
  grid.y_origin = header("yllcorner");
  grid.cell_size = header("cellsize");
  grid.nodata = header("nodata_value");
  grid.heights.resize(grid.cols * grid.rows);
  std::string word;
  for (double& value : grid.heights) {
    if (!(in >> word)) throw file_error(file, fmt::format("truncated: expected {} × {} values", grid.rows, grid.cols));
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
    if (ec != std::errc() || end != word.data() + word.size())
      throw file_error(file, fmt::format("expected a number, found '{}'", word));
    if (value == grid.nodata) value = kNaN;
  }
  return grid;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

/// Linear interpolation between closest ranks (the "type 7" percentile of sorted values).
double percentile(const std::vector<double>& sorted, double p) {
  const double position = p / 100 * double(sorted.size() - 1);
  const std::size_t below = std::size_t(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  return sorted[below] + (position - double(below)) * (sorted[above] - sorted[below]);
}

std::string csv_text(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// A unit as a column name's suffix: "m²" → "m2", "m/s" → "m_per_s".
std::string column_unit(std::string unit) {
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"²", "2"}, {"³", "3"}, {"/", "_per_"}})
    for (std::size_t at = unit.find(from); at != std::string::npos; at = unit.find(from, at + to.size()))
      unit.replace(at, from.size(), to);
  return unit;
}

/// A TOML value as a table shows it: a string without its quotes.
std::string choice_text(const std::string& toml_text) {
  if (toml_text.size() >= 2 && (toml_text.front() == '"' || toml_text.front() == '\'') && toml_text.back() == toml_text.front())
    return toml_text.substr(1, toml_text.size() - 2);
  return toml_text;
}

void write_member_table(const fs::path& file, const EnsembleRun& run, const std::vector<MemberRecord>& records) {
  write_atomically(file, [&](std::ostream& out) {
    out << "index,status,region_x,region_y";
    for (const SampledParameter& p : run.spec.parameters) out << ',' << csv_text(p.key);
    for (const OutputDecl& d : run.values) out << ',' << csv_text(d.unit.empty() ? d.name : d.name + "_" + column_unit(d.unit));
    out << ",final_time_s,iterations,stop,error\n";
    auto value_of = [](const std::vector<std::pair<std::string, double>>& entries, const std::string& key) {
      double value = kNaN;
      for (const auto& [k, v] : entries)
        if (k == key) value = v;
      return value;
    };
    for (const MemberRecord& r : records) {
      out << fmt::format("{},{},{},{}", r.index, r.ok ? "ok" : "failed", r.x, r.y);
      for (const SampledParameter& p : run.spec.parameters) {
        const double value = value_of(r.parameters, p.key);
        // A choice shows the value drawn (its index is what the member's record keeps).
        if (p.distribution == SampledParameter::Distribution::Choice && value >= 0 && value < double(p.choices.size()))
          out << ',' << csv_text(choice_text(p.choices[std::size_t(value)]));
        else
          out << fmt::format(",{}", value);
      }
      for (const OutputDecl& d : run.values) out << fmt::format(",{}", value_of(r.values, d.name));
      out << fmt::format(",{},{},{},{}\n", r.final_time, r.iterations, csv_text(r.stop), csv_text(r.error));
    }
  });
}

/// A share over the members from above: a block of pixels per cell, light grey where it is 0, the
/// colormap over (0, max] elsewhere (a probability map's values are mostly small), a colour bar and
/// a title.
void write_share_picture(const fs::path& file, const HeightGrid& share, const std::string& what, std::size_t members) {
  const int scale = std::max(1, int(900 / std::max(share.cols, share.rows)));
  const int width = int(share.cols) * scale, height = int(share.rows) * scale;
  const int top = 40, bar = 110;
  double highest = 0;
  for (double p : share.heights) highest = std::max(highest, p);
  if (highest <= 0) highest = 1;
  Image image(width + bar + 20, height + top + 10);
  for (std::size_t r = 0; r < share.rows; ++r)
    for (std::size_t c = 0; c < share.cols; ++c) {
      const double p = share.at(r, c);
      // White off the surface, grey where no member reached.
      const Rgb colour = p == share.nodata ? Rgb{255, 255, 255} : p > 0 ? colormap(p / highest) : Rgb{225, 225, 225};
      image.fill_rect(int(c) * scale, top + int(r) * scale, int(c + 1) * scale, top + int(r + 1) * scale, colour);
    }
  const int x0 = width + 20;
  for (int y = 0; y < height; ++y)
    image.fill_rect(x0, top + y, x0 + 20, top + y + 1, colormap(1.0 - double(y) / std::max(1, height - 1)));
  image.text(x0 + 26, top, fmt::format("{:.3g}", highest), {0, 0, 0}, 2);
  image.text(x0 + 26, top + height / 2 - 7, fmt::format("{:.3g}", highest / 2), {0, 0, 0}, 2);
  image.text(x0 + 26, top + height - 14, "0", {0, 0, 0}, 2);
  const std::string title = fmt::format("{}, {} members ({:.0f} m cells)", what, members, share.cell_size);
  image.text(4, 8, title, {0, 0, 0}, Image::text_width(title, 2) + 8 <= image.width ? 2 : 1);
  write_png(image, file);
}

/// "{members}" and "{percentile}" of a declared description replaced.
std::string describe(std::string text, std::size_t members, double percentile = 0) {
  auto replace = [&](const std::string& placeholder, const std::string& value) {
    for (std::size_t at = text.find(placeholder); at != std::string::npos; at = text.find(placeholder, at + value.size()))
      text.replace(at, placeholder.size(), value);
  };
  replace("{members}", fmt::format("{}", members));
  replace("{percentile}", fmt::format("{}", percentile));
  return text;
}

/// One combined output: every ok member's grid, cell by cell, then its combinations written.
void reduce_output(const EnsembleRun& run, const OutputDecl& output, const std::vector<MemberRecord>& records,
                   std::size_t members) {
  HeightGrid frame;
  fs::path frame_file;
  std::vector<std::uint32_t> reached;
  std::vector<double> sum;
  std::vector<std::vector<double>> values;  // per cell, the members' values
  for (const MemberRecord& record : records) {
    if (!record.ok) continue;
    const fs::path file = member_grid_path(run.outdir, record.index, output.name);
    HeightGrid grid = read_member_grid(file);
    if (frame.cols == 0) {
      frame = grid;
      frame_file = file;
      fs::path prj = file;
      prj.replace_extension(".prj");
      if (fs::exists(prj)) frame.crs = read_text(prj);
      const std::size_t cells = grid.heights.size();
      reached.assign(cells, 0), sum.assign(cells, 0);
      values.assign(cells, {});
    } else if (!same_frame(frame, grid)) {
      throw InputError(fmt::format("{} and {}: the members' '{}' grids differ ({} × {} cells of {} at ({}, {}) against "
                                   "{} × {} of {} at ({}, {})): give the model a grid that does not depend on the "
                                   "member (bodyfit plugins --describe names its parameters)",
                                   frame_file.string(), file.string(), output.name, frame.cols, frame.rows,
                                   frame.cell_size, frame.x_origin, frame.y_origin, grid.cols, grid.rows,
                                   grid.cell_size, grid.x_origin, grid.y_origin));
    }
    for (std::size_t c = 0; c < grid.heights.size(); ++c) {
      const double t = grid.heights[c];
      if (std::isnan(t)) continue;
      ++reached[c];
      sum[c] += t;
      values[c].push_back(t);
    }
  }
  // Off the surface nothing is combined: a cell belongs to the grid's domain when its centre lies
  // on the surface seen from above, or when a member gave it a value.
  std::vector<bool> domain(frame.heights.size(), true);
  if (!run.domain.footprint.empty()) {
    domain = cells_inside(run.domain.footprint, frame.cols, frame.rows, frame.x_origin, frame.y_origin, frame.cell_size);
    for (std::size_t c = 0; c < domain.size(); ++c) domain[c] = domain[c] || reached[c] > 0;
  }
  auto raster = [&](auto&& value_of) {
    HeightGrid out = frame;
    out.nodata = kGridNodata;
    for (std::size_t c = 0; c < out.heights.size(); ++c) {
      const double v = domain[c] ? value_of(c) : kNaN;
      out.heights[c] = std::isnan(v) ? out.nodata : v;
    }
    return out;
  };
  for (auto& cell : values) std::sort(cell.begin(), cell.end());
  for (const Combine& how : output.ensemble) {
    const fs::path file = run.outdir / (how.name + ".asc");
    switch (how.op) {
      case Combine::Op::Share: {
        const HeightGrid share = raster([&](std::size_t c) { return double(reached[c]) / double(members); });
        write_ensemble_raster(file, share, {.units = how.unit, .description = describe(how.description, members)});
        std::string what = how.name;
        std::replace(what.begin(), what.end(), '_', ' ');
        write_share_picture(run.outdir / (how.name + ".png"), share, what, members);
        break;
      }
      case Combine::Op::Mean:
        write_ensemble_raster(file, raster([&](std::size_t c) { return reached[c] ? sum[c] / double(reached[c]) : kNaN; }),
                              {.units = how.unit, .description = describe(how.description, members)});
        break;
      case Combine::Op::Percentiles:
        for (double p : run.spec.percentiles) {
          std::string suffix = fmt::format("{}", p);
          std::replace(suffix.begin(), suffix.end(), '.', '_');
          write_ensemble_raster(run.outdir / (how.name + suffix + ".asc"), raster([&](std::size_t c) {
                                  return values[c].empty() ? kNaN : percentile(values[c], p);
                                }),
                                {.units = how.unit, .description = describe(how.description, members, p)});
        }
        break;
    }
  }
}

}  // namespace

void write_ensemble_raster(const fs::path& file, const HeightGrid& grid, const RasterMetadata& metadata) {
  write_raster(file, grid, metadata);
  // The GeoTIFF a GIS opens as it is (CRS, NODATA, units), beside the ESRI grid scripts read.
  if constexpr (config::have_gdal) write_raster(fs::path(file).replace_extension(".tif"), grid, metadata);
}

ReduceReport reduce_ensemble(const EnsembleRun& run) {
  const std::size_t n = run.spec.members;
  std::vector<MemberRecord> records(n);
  ReduceReport report;
  for (std::size_t i = 0; i < n; ++i) {
    if (!read_member_record(run, i, records[i]))
      throw InputError(fmt::format("{}: member {} has no complete result", member_record_path(run.outdir, i).string(), i));
    if (records[i].ok) ++report.ok;
    else ++report.failed;
  }
  write_member_table(run.outdir / "members.csv", run, records);
  if (report.ok == 0) {
    spdlog::error("no member completed: nothing combined (members.csv lists the errors)");
    return report;
  }
  for (const OutputDecl& output : run.combined) reduce_output(run, output, records, report.ok);
  return report;
}

}  // namespace bodyfit
