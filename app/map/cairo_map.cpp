// The map module: fire maps (map.hpp) drawn with Cairo. The layout comes from the core
// (map_layout, scale_bar, isochrone_levels, isochrone_segments), so what the tests check against
// is what is drawn; this file only paints.
#include "map_module.hpp"

#include <bodyfit/config.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/app/map.hpp>
#include <bodyfit/app/render.hpp>

#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace bodyfit::map_module {
namespace {

constexpr double kDegree = M_PI / 180.0;

void set_colour(cairo_t* cr, Rgb c, double alpha = 1) { cairo_set_source_rgba(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, alpha); }

// Text sizes follow the picture's height so that a large map stays readable.
struct Fonts {
  double title, body, small;
};

void select_font(cairo_t* cr, double size, bool bold = false) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
}

double text_width(cairo_t* cr, const std::string& text) {
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  return extents.x_advance;
}

// Text with its baseline starting at (x, y); a white halo keeps it readable over the terrain.
void draw_text(cairo_t* cr, double x, double y, const std::string& text, bool halo = false, Rgb colour = {0, 0, 0}) {
  cairo_move_to(cr, x, y);
  if (halo) {
    cairo_text_path(cr, text.c_str());
    cairo_set_source_rgba(cr, 1, 1, 1, 0.9);
    cairo_set_line_width(cr, 3);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_stroke(cr);
    cairo_move_to(cr, x, y);
  }
  set_colour(cr, colour);
  cairo_show_text(cr, text.c_str());
}

// A triangle in pixels, always counter-clockwise on screen, so that a path of many of them filled
// with the non-zero rule is their union.
void add_triangle(cairo_t* cr, MapPixel a, MapPixel b, MapPixel c) {
  const double cross = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (cross > 0) std::swap(b, c);
  cairo_move_to(cr, a.x, a.y);
  cairo_line_to(cr, b.x, b.y);
  cairo_line_to(cr, c.x, c.y);
  cairo_close_path(cr);
}

std::array<MapPixel, 3> face_pixels(const SurfaceMesh& mesh, FaceHandle f, const MapLayout& layout) {
  std::array<MapPixel, 3> p;
  int i = 0;
  for (auto v : mesh.fv_range(f)) {
    const Vec3& x = mesh.point(v);
    p[i++] = layout.to_pixel(x[0], x[1]);
  }
  return p;
}

// Grey of a Lambertian hillshade: 60 in the shadow, 255 facing the sun. Heights scaled by
// z_factor tilt the normal (−k·f_x, −k·f_y, 1) of z = k·f(x, y): its plan components times k.
double hillshade_grey(const Vec3& normal, const Vec3& sun, double z_factor) {
  Vec3 n = normal;
  if (n[2] < 0) n = -n;
  n[0] *= z_factor, n[1] *= z_factor;
  n.normalize();
  return (60 + 195 * std::max(0.0, OpenMesh::dot(n, sun))) / 255;
}

Vec3 sun_direction(const MapOptions& options) {
  const double az = options.sun_azimuth * kDegree, alt = options.sun_altitude * kDegree;
  return Vec3(std::sin(az) * std::cos(alt), std::cos(az) * std::cos(alt), std::sin(alt));
}

void draw_hillshade(cairo_t* cr, const SurfaceMesh& mesh, const MapLayout& layout, const MapOptions& options) {
  // One path per grey level: 256 fills instead of one per face. No antialiasing, so that
  // neighbouring triangles tile the plane without seams.
  const Vec3 sun = sun_direction(options);
  std::vector<std::vector<FaceHandle>> by_grey(256);
  for (auto f : mesh.faces()) {
    const double grey = hillshade_grey(face_normal(mesh, f), sun, options.z_factor);
    by_grey[std::size_t(std::lround(grey * 255))].push_back(f);
  }
  cairo_save(cr);
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
  for (std::size_t g = 0; g < by_grey.size(); ++g) {
    if (by_grey[g].empty()) continue;
    for (FaceHandle f : by_grey[g]) {
      auto p = face_pixels(mesh, f, layout);
      add_triangle(cr, p[0], p[1], p[2]);
    }
    const double grey = double(g) / 255;
    cairo_set_source_rgb(cr, grey, grey, grey);
    cairo_fill(cr);
  }
  cairo_restore(cr);
}

void draw_burnt_area(cairo_t* cr, const SurfaceMesh& mesh, const MapLayout& layout, const MapOptions& options) {
  for (auto f : mesh.faces())
    if (mesh.inside(f)) {
      auto p = face_pixels(mesh, f, layout);
      add_triangle(cr, p[0], p[1], p[2]);
    }
  set_colour(cr, options.burnt_color, options.burnt_opacity);
  cairo_fill(cr);
  // The perimeter ∂G, as the mesh carries it.
  for (auto e : mesh.edges())
    if (mesh.interface(e)) {
      const Vec3& a = mesh.point(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0)));
      const Vec3& b = mesh.point(mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)));
      const MapPixel pa = layout.to_pixel(a[0], a[1]), pb = layout.to_pixel(b[0], b[1]);
      cairo_move_to(cr, pa.x, pa.y);
      cairo_line_to(cr, pb.x, pb.y);
    }
  cairo_set_source_rgb(cr, 0.45, 0, 0);
  cairo_set_line_width(cr, 1.5);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_stroke(cr);
}

void draw_isochrones(cairo_t* cr, const MapLayers& layers, const std::vector<double>& levels, const MapLayout& layout,
                     const MapOptions& options, const Fonts& fonts) {
  const double interval = isochrone_interval(layers.arrival, options);
  std::vector<std::vector<std::array<Vec3, 2>>> lines;
  for (double level : levels) lines.push_back(isochrone_segments(layers.arrival, level));
  auto add_segments = [&](const std::vector<std::array<Vec3, 2>>& segments) {
    for (const auto& s : segments) {
      const MapPixel a = layout.to_pixel(s[0][0], s[0][1]), b = layout.to_pixel(s[1][0], s[1][1]);
      cairo_move_to(cr, a.x, a.y);
      cairo_line_to(cr, b.x, b.y);
    }
  };
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (std::size_t i = 0; i < levels.size(); ++i) {
    // A dark casing under the coloured line: yellow on a light hillshade stays visible.
    add_segments(lines[i]);
    cairo_set_source_rgba(cr, 0, 0, 0, 0.6);
    cairo_set_line_width(cr, 4);
    cairo_stroke(cr);
    add_segments(lines[i]);
    set_colour(cr, isochrone_colour(i, levels.size()));
    cairo_set_line_width(cr, 2.5);
    cairo_stroke(cr);
  }
  // Each line labelled once, as far north as it can be without covering another line's label
  // (a column of labels a reader scans down): candidates from its northernmost segment southwards.
  select_font(cr, fonts.small, true);
  std::vector<std::string> labels(levels.size());
  std::vector<std::vector<LabelBox>> candidates(levels.size());
  for (std::size_t i = 0; i < levels.size(); ++i) {
    labels[i] = time_label(levels[i], interval, options);
    const double w = text_width(cr, labels[i]), h = fonts.small;
    std::vector<MapPixel> mids;
    for (const auto& s : lines[i]) mids.push_back(layout.to_pixel(0.5 * (s[0][0] + s[1][0]), 0.5 * (s[0][1] + s[1][1])));
    std::sort(mids.begin(), mids.end(), [](const MapPixel& a, const MapPixel& b) { return a.y < b.y; });
    // At most 64 tries a line: a label needs room, not every position.
    const std::size_t step = std::max<std::size_t>(1, mids.size() / 64);
    for (std::size_t k = 0; k < mids.size(); k += step)
      candidates[i].push_back({mids[k].x - w / 2 - 2, mids[k].y - 5 - h, mids[k].x + w / 2 + 2, mids[k].y - 1});
  }
  const std::vector<int> chosen = place_labels(candidates, layout);
  for (std::size_t i = 0; i < levels.size(); ++i) {
    if (chosen[i] < 0) continue;
    const LabelBox& box = candidates[i][std::size_t(chosen[i])];
    draw_text(cr, box.x0 + 2, box.y1 - 4, labels[i], true);
  }
}

void add_star(cairo_t* cr, MapPixel centre, double radius) {
  for (int k = 0; k < 10; ++k) {
    const double r = k % 2 ? 0.45 * radius : radius, angle = -M_PI / 2 + k * M_PI / 5;
    const double x = centre.x + r * std::cos(angle), y = centre.y + r * std::sin(angle);
    if (k == 0) cairo_move_to(cr, x, y);
    else cairo_line_to(cr, x, y);
  }
  cairo_close_path(cr);
}

void draw_star(cairo_t* cr, MapPixel centre, double radius, Rgb colour) {
  add_star(cr, centre, radius);
  set_colour(cr, colour);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1.2);
  cairo_stroke(cr);
}

void draw_scale_bar(cairo_t* cr, const MapLayout& layout, const Fonts& fonts) {
  const ScaleBar bar = scale_bar(layout);
  select_font(cr, fonts.small);
  const double label_w = text_width(cr, bar.label);
  // A light box behind it, the bar (4 px, centred on bar.left.y), ticks above it at 0, ½ and 1.
  cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
  cairo_rectangle(cr, bar.left.x - 8, bar.left.y - 12 - fonts.small, bar.pixels + label_w / 2 + 16, 22 + fonts.small);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, bar.left.x, bar.left.y - 2, bar.pixels, 4);
  cairo_fill(cr);
  cairo_set_line_width(cr, 1.5);
  for (double at : {0.75, bar.pixels / 2, bar.pixels - 0.75}) {
    cairo_move_to(cr, bar.left.x + at, bar.left.y - 2);
    cairo_line_to(cr, bar.left.x + at, bar.left.y - 8);
  }
  cairo_stroke(cr);
  draw_text(cr, bar.left.x - text_width(cr, "0") / 2, bar.left.y - 10, "0");
  draw_text(cr, bar.left.x + bar.pixels - label_w / 2, bar.left.y - 10, bar.label);
}

void draw_north_arrow(cairo_t* cr, const MapLayout& layout, const Fonts& fonts) {
  const double size = std::clamp(0.05 * (layout.panel_bottom - layout.panel_top), 18.0, 40.0);
  const double x = layout.panel_right - size - 6, y = layout.panel_top + size * 1.5 + 6;
  cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
  cairo_arc(cr, x, y - size * 0.35, size * 1.05, 0, 2 * M_PI);
  cairo_fill(cr);
  // Two halves of an arrowhead pointing to +y (north): the left dark, the right light.
  cairo_move_to(cr, x, y - size);
  cairo_line_to(cr, x - size * 0.4, y);
  cairo_line_to(cr, x, y - size * 0.3);
  cairo_close_path(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_fill(cr);
  cairo_move_to(cr, x, y - size);
  cairo_line_to(cr, x + size * 0.4, y);
  cairo_line_to(cr, x, y - size * 0.3);
  cairo_close_path(cr);
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  cairo_stroke(cr);
  select_font(cr, fonts.body, true);
  draw_text(cr, x - text_width(cr, "N") / 2, y - size - 4, "N");
}

// The burnt area at a time (MapLayers::burnt_at): the raster's cells reached by then, filled as one
// path (one coat of the colour), outlined where a burnt cell meets an unburnt one or the edge.
void draw_burnt_cells(cairo_t* cr, const HeightGrid& arrival, const std::vector<char>& cells, const MapLayout& layout,
                      const MapOptions& options) {
  const auto burnt = [&](long row, long col) {
    return row >= 0 && col >= 0 && std::size_t(row) < arrival.rows && std::size_t(col) < arrival.cols &&
           cells[std::size_t(row) * arrival.cols + std::size_t(col)];
  };
  // Corner (i, j) of the cell grid: i columns east of the west edge, j rows south of the north edge.
  const auto corner = [&](std::size_t i, std::size_t j) {
    return layout.to_pixel(arrival.x_origin + double(i) * arrival.cell_size,
                           arrival.y_origin + double(arrival.rows - j) * arrival.cell_size);
  };
  for (std::size_t row = 0; row < arrival.rows; ++row)
    for (std::size_t col = 0; col < arrival.cols; ++col)
      if (burnt(long(row), long(col))) {
        const MapPixel a = corner(col, row), b = corner(col + 1, row + 1);
        cairo_rectangle(cr, a.x, a.y, b.x - a.x, b.y - a.y);
      }
  set_colour(cr, options.burnt_color, options.burnt_opacity);
  cairo_fill(cr);
  const auto edge = [&](MapPixel a, MapPixel b) {
    cairo_move_to(cr, a.x, a.y);
    cairo_line_to(cr, b.x, b.y);
  };
  for (std::size_t row = 0; row < arrival.rows; ++row)
    for (std::size_t col = 0; col < arrival.cols; ++col) {
      const long r = long(row), c = long(col);
      if (!burnt(r, c)) continue;
      if (!burnt(r - 1, c)) edge(corner(col, row), corner(col + 1, row));
      if (!burnt(r + 1, c)) edge(corner(col, row + 1), corner(col + 1, row + 1));
      if (!burnt(r, c - 1)) edge(corner(col, row), corner(col, row + 1));
      if (!burnt(r, c + 1)) edge(corner(col + 1, row), corner(col + 1, row + 1));
    }
  cairo_set_source_rgb(cr, 0.45, 0, 0);
  cairo_set_line_width(cr, 1.5);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_stroke(cr);
}

void draw_legend(cairo_t* cr, const MapLayers& layers, double burnt_area, const std::vector<double>& levels,
                 const MapLayout& layout, const MapOptions& options, const Fonts& fonts) {
  const bool burnt = burnt_area > 0;
  const double x = layout.legend_left + 10, swatch = 1.6 * fonts.body, line = 1.7 * fonts.body;
  double y = layout.panel_top + fonts.body;
  const double bottom = layout.height - 2 * fonts.body;
  auto text_at = [&](double dx, const std::string& text, bool bold = false) {
    select_font(cr, fonts.body, bold);
    draw_text(cr, x + dx, y + 0.35 * fonts.body, text);
  };
  text_at(0, "Legend", true);
  y += 1.5 * line;
  if (burnt) {
    cairo_set_source_rgb(cr, 0.75, 0.75, 0.75);
    cairo_rectangle(cr, x, y - swatch / 3, swatch, 2 * swatch / 3);
    cairo_fill(cr);
    set_colour(cr, options.burnt_color, options.burnt_opacity);
    cairo_rectangle(cr, x, y - swatch / 3, swatch, 2 * swatch / 3);
    cairo_fill(cr);
    const std::string when =
        layers.burnt_at ? " at " + time_label(*layers.burnt_at, isochrone_interval(layers.arrival, options), options)
                        : "";
    text_at(swatch + 8, fmt::format("Burnt area{}, {:.3g} km\u00b2", when, burnt_area / 1e6));
    y += line;
    cairo_move_to(cr, x, y);
    cairo_line_to(cr, x + swatch, y);
    cairo_set_source_rgb(cr, 0.45, 0, 0);
    cairo_set_line_width(cr, 1.5);
    cairo_stroke(cr);
    text_at(swatch + 8, "Fire perimeter");
    y += line;
  }
  if (!layers.ignitions.empty()) {
    draw_star(cr, {x + swatch / 2, y}, 0.45 * swatch, options.ignition_color);
    text_at(swatch + 8, layers.ignitions.size() > 1 ? "Ignition points" : "Ignition point");
    y += line;
  }
  if (!levels.empty()) {
    y += 0.4 * line;
    text_at(0, "Arrival time (isochrones)", true);
    y += line;
    const double interval = isochrone_interval(layers.arrival, options);
    for (std::size_t i = 0; i < levels.size(); ++i) {
      if (y > bottom - 3 * line) {
        text_at(swatch + 8, fmt::format("... {} more", levels.size() - i));
        y += line;
        break;
      }
      cairo_move_to(cr, x, y);
      cairo_line_to(cr, x + swatch, y);
      cairo_set_source_rgba(cr, 0, 0, 0, 0.6);
      cairo_set_line_width(cr, 4);
      cairo_stroke_preserve(cr);
      set_colour(cr, isochrone_colour(i, levels.size()));
      cairo_set_line_width(cr, 2.5);
      cairo_stroke(cr);
      text_at(swatch + 8, time_label(levels[i], interval, options));
      y += line;
    }
  }
  y += 0.4 * line;
  cairo_pattern_t* ramp = cairo_pattern_create_linear(x, 0, x + swatch, 0);
  const double lo = 60.0 / 255;
  cairo_pattern_add_color_stop_rgb(ramp, 0, lo, lo, lo);
  cairo_pattern_add_color_stop_rgb(ramp, 1, 1, 1, 1);
  cairo_set_source(cr, ramp);
  cairo_rectangle(cr, x, y - swatch / 3, swatch, 2 * swatch / 3);
  cairo_fill(cr);
  cairo_pattern_destroy(ramp);
  cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
  cairo_set_line_width(cr, 0.8);
  cairo_rectangle(cr, x, y - swatch / 3, swatch, 2 * swatch / 3);
  cairo_stroke(cr);
  text_at(swatch + 8, "Hillshade");
  y += 0.9 * line;
  select_font(cr, fonts.small);
  draw_text(cr, x + swatch + 8, y, fmt::format("sun at {:g}\u00b0, {:g}\u00b0 high", options.sun_azimuth, options.sun_altitude));
  if (options.z_factor != 1) draw_text(cr, x + swatch + 8, y + 1.2 * fonts.small, fmt::format("heights \u00d7 {:g}", options.z_factor));
}

void draw_title_and_caption(cairo_t* cr, const MapLayers& layers, const MapLayout& layout, const MapOptions& options,
                            const Fonts& fonts) {
  select_font(cr, fonts.title, true);
  draw_text(cr, layout.panel_left, layout.panel_top - 0.45 * fonts.title, options.title);
  std::vector<std::string> parts;
  parts.push_back(layers.crs_name.empty() ? std::string("x, y in metres (no coordinate system given)")
                                          : fmt::format("Coordinate system: {}", layers.crs_name));
  if (const std::string when = map_time_caption(layers); !when.empty()) parts.push_back(when);
  parts.push_back("north up");
  parts.push_back(fmt::format("drawn by bodyfit {}", config::version));
  std::string caption;
  for (const auto& part : parts) caption += (caption.empty() ? "" : "  \u00b7  ") + part;
  select_font(cr, fonts.small);
  draw_text(cr, layout.panel_left, layout.height - 0.6 * fonts.small, caption, false, {60, 60, 60});
}

bool any_burnt(const SurfaceMesh& mesh) {
  for (auto f : mesh.faces())
    if (mesh.inside(f)) return true;
  return false;
}

void draw(cairo_t* cr, const SurfaceMesh& mesh, const MapLayers& layers, const MapOptions& options) {
  double xmin = std::numeric_limits<double>::infinity(), ymin = xmin, xmax = -xmin, ymax = -xmin;
  for (auto v : mesh.vertices()) {
    const Vec3& p = mesh.point(v);
    xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
    ymin = std::min(ymin, p[1]), ymax = std::max(ymax, p[1]);
  }
  const MapLayout layout = map_layout(xmin, ymin, xmax, ymax, options);
  const Fonts fonts{std::clamp(0.032 * options.height, 16.0, 40.0), std::clamp(0.019 * options.height, 11.0, 24.0),
                    std::clamp(0.016 * options.height, 10.0, 20.0)};
  std::vector<double> levels = isochrone_levels(layers.arrival, options);
  std::vector<char> cells;  // the burnt area at layers.burnt_at: the raster's cells reached by then
  double burnt_area = 0;
  if (layers.burnt_at) {
    std::erase_if(levels, [&](double level) { return level > *layers.burnt_at; });
    cells = burnt_cells(layers.arrival, *layers.burnt_at);
    burnt_area = double(std::count(cells.begin(), cells.end(), 1)) * layers.arrival.cell_size * layers.arrival.cell_size;
  } else if (mesh.has_regions() && any_burnt(mesh)) {
    burnt_area = region_area(mesh, kInside);
  }

  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_save(cr);
  cairo_rectangle(cr, layout.panel_left, layout.panel_top, layout.panel_right - layout.panel_left,
                  layout.panel_bottom - layout.panel_top);
  cairo_clip(cr);
  draw_hillshade(cr, mesh, layout, options);
  if (!layers.burnt_area) burnt_area = 0;
  if (burnt_area > 0 && layers.burnt_at) draw_burnt_cells(cr, layers.arrival, cells, layout, options);
  else if (burnt_area > 0) draw_burnt_area(cr, mesh, layout, options);
  if (!levels.empty()) draw_isochrones(cr, layers, levels, layout, options, fonts);
  for (const Vec3& p : layers.ignitions) draw_star(cr, layout.to_pixel(p[0], p[1]), 9, options.ignition_color);
  cairo_restore(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, std::floor(layout.panel_left) - 0.5, std::floor(layout.panel_top) - 0.5,
                  std::ceil(layout.panel_right) - std::floor(layout.panel_left) + 1,
                  std::ceil(layout.panel_bottom) - std::floor(layout.panel_top) + 1);
  cairo_stroke(cr);
  draw_scale_bar(cr, layout, fonts);
  draw_north_arrow(cr, layout, fonts);
  draw_legend(cr, layers, burnt_area, levels, layout, options, fonts);
  draw_title_and_caption(cr, layers, layout, options, fonts);
}

cairo_status_t append_bytes(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

bool draw_png(const SurfaceMesh& mesh, const MapLayers& layers, const MapOptions& options, std::string& png,
              std::string& error) {
  try {
    std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
        cairo_image_surface_create(CAIRO_FORMAT_RGB24, options.width, options.height), &cairo_surface_destroy);
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), &cairo_destroy);
    draw(cr.get(), mesh, layers, options);
    if (cairo_status_t status = cairo_status(cr.get()); status != CAIRO_STATUS_SUCCESS) {
      error = fmt::format("Cairo could not draw the map: {}", cairo_status_to_string(status));
      return false;
    }
    cairo_surface_flush(surface.get());
    png.clear();
    if (cairo_status_t status = cairo_surface_write_to_png_stream(surface.get(), append_bytes, &png);
        status != CAIRO_STATUS_SUCCESS) {
      error = fmt::format("Cairo could not encode the PNG: {}", cairo_status_to_string(status));
      return false;
    }
    return true;
  } catch (const std::exception& e) {
    error = e.what();
    return false;
  }
}

const Api kApi{kApiVersion, &draw_png};

}  // namespace
}  // namespace bodyfit::map_module

extern "C" __attribute__((visibility("default"))) const bodyfit::map_module::Api* bodyfit_map_api() {
  return &bodyfit::map_module::kApi;
}
