#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/app/render.hpp>

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace bodyfit {
namespace {

/// 5×7 glyphs, one byte per row (bit 4 = leftmost column).
const std::unordered_map<char, std::array<std::uint8_t, 7>>& font() {
  static const std::unordered_map<char, std::array<std::uint8_t, 7>> glyphs{
    {'0', {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}},
    {'1', {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'2', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}},
    {'3', {0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e}},
    {'4', {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}},
    {'5', {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}},
    {'6', {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}},
    {'7', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}},
    {'9', {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}},
    {'A', {0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11}},
    {'B', {0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e}},
    {'C', {0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e}},
    {'D', {0x1c, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1c}},
    {'E', {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f}},
    {'F', {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10}},
    {'G', {0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f}},
    {'H', {0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11}},
    {'I', {0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
    {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f}},
    {'M', {0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11}},
    {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e}},
    {'P', {0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10}},
    {'Q', {0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d}},
    {'R', {0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11}},
    {'S', {0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e}},
    {'T', {0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e}},
    {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a}},
    {'X', {0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x11, 0x0a, 0x04, 0x04, 0x04}},
    {'Z', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08}},
    {'-', {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00}},
    {'=', {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {':', {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00}},
    {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1f}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'<', {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}},
    {'>', {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}},
    {'|', {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'*', {0x00, 0x04, 0x15, 0x0e, 0x15, 0x04, 0x00}},
    {'\'', {0x04, 0x04, 0x08, 0x00, 0x00, 0x00, 0x00}},
    {'[', {0x0e, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0e}},
    {']', {0x0e, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0e}},
  };
  return glyphs;
}

void png_write_to_stream(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::ostream*>(png_get_io_ptr(png));
  out->write(reinterpret_cast<const char*>(data), std::streamsize(length));
}
void png_flush_stream(png_structp png) { static_cast<std::ostream*>(png_get_io_ptr(png))->flush(); }
void png_read_from_stream(png_structp png, png_bytep data, png_size_t length) {
  auto* in = static_cast<std::istream*>(png_get_io_ptr(png));
  in->read(reinterpret_cast<char*>(data), std::streamsize(length));
  if (in->gcount() != std::streamsize(length)) png_error(png, "truncated file");
}
[[noreturn]] void png_fail(png_structp, png_const_charp message) { throw InputError(message); }
void png_warn(png_structp, png_const_charp) {}

Rgb shade(Rgb c, double intensity) {
  Rgb out;
  for (int k = 0; k < 3; ++k) out[k] = std::uint8_t(std::clamp(c[k] * intensity, 0.0, 255.0));
  return out;
}

std::string format_value(double v) {
  if (v == 0) return "0";
  double a = std::abs(v);
  if (a >= 1e-2 && a < 1e4) return fmt::format("{:.3g}", v);
  return fmt::format("{:.2e}", v);
}

}  // namespace

Image::Image(int w, int h, Rgb background) : width(w), height(h), pixels(std::size_t(w) * h * 3) {
  for (std::size_t i = 0; i < pixels.size(); i += 3)
    pixels[i] = background[0], pixels[i + 1] = background[1], pixels[i + 2] = background[2];
}

Rgb Image::at(int x, int y) const {
  std::size_t i = (std::size_t(y) * width + x) * 3;
  return {pixels[i], pixels[i + 1], pixels[i + 2]};
}

void Image::set(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= width || y >= height) return;
  std::size_t i = (std::size_t(y) * width + x) * 3;
  pixels[i] = c[0], pixels[i + 1] = c[1], pixels[i + 2] = c[2];
}

void Image::line(double x0, double y0, double x1, double y1, Rgb c, double w) {
  const double length = std::hypot(x1 - x0, y1 - y0);
  const int steps = std::max(1, int(std::ceil(length * 2)));
  const double r = std::max(0.5, w / 2);
  const int ir = int(std::ceil(r));
  for (int s = 0; s <= steps; ++s) {
    double x = x0 + (x1 - x0) * s / steps, y = y0 + (y1 - y0) * s / steps;
    for (int dy = -ir; dy <= ir; ++dy)
      for (int dx = -ir; dx <= ir; ++dx) {
        int px = int(std::floor(x)) + dx, py = int(std::floor(y)) + dy;
        if ((px + 0.5 - x) * (px + 0.5 - x) + (py + 0.5 - y) * (py + 0.5 - y) <= r * r) set(px, py, c);
      }
  }
}

void Image::fill_rect(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(width, x1); ++x) set(x, y, c);
}

int Image::text_width(const std::string& s, int scale) { return int(s.size()) * 6 * scale; }

int Image::text(int x, int y, const std::string& s, Rgb c, int scale) {
  int cx = x;
  for (char ch : s) {
    auto it = font().find(char(std::toupper(static_cast<unsigned char>(ch))));
    if (it != font().end())
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col)
          if (it->second[row] & (0x10 >> col)) fill_rect(cx + col * scale, y + row * scale, cx + (col + 1) * scale,
                                                          y + (row + 1) * scale, c);
    cx += 6 * scale;
  }
  return cx - x;
}

void write_png(const Image& image, const std::filesystem::path& file) {
  if (image.width <= 0 || image.height <= 0) throw InputError(fmt::format("{}: empty image", file.string()));
  write_atomically(file, [&](std::ostream& out) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, png_fail, png_warn);
    png_infop info = png_create_info_struct(png);
    try {
      png_set_write_fn(png, &out, png_write_to_stream, png_flush_stream);
      png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGB,
                   PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
      png_write_info(png, info);
      for (int y = 0; y < image.height; ++y)
        png_write_row(png, const_cast<png_bytep>(image.pixels.data() + std::size_t(y) * image.width * 3));
      png_write_end(png, nullptr);
    } catch (...) {
      png_destroy_write_struct(&png, &info);
      throw;
    }
    png_destroy_write_struct(&png, &info);
  });
}

Image read_png(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw file_error(file, "cannot open");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, png_fail, png_warn);
  png_infop info = png_create_info_struct(png);
  Image image;
  try {
    png_set_read_fn(png, &in, png_read_from_stream);
    png_read_info(png, info);
    png_set_expand(png);
    png_set_strip_16(png);
    png_set_strip_alpha(png);
    png_set_gray_to_rgb(png);
    png_read_update_info(png, info);
    image = Image(int(png_get_image_width(png, info)), int(png_get_image_height(png, info)));
    for (int y = 0; y < image.height; ++y) png_read_row(png, image.pixels.data() + std::size_t(y) * image.width * 3, nullptr);
  } catch (const InputError& e) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw file_error(file, e.what());
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

Rgb colormap(double s) {
  // Anchors of matplotlib's viridis at s = 0, 1/8, ..., 1 (linear interpolation between them).
  static const double anchors[9][3] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},  {44, 113, 142}, {33, 144, 141},
                                       {39, 173, 129}, {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
  if (!std::isfinite(s)) return {128, 128, 128};
  s = std::clamp(s, 0.0, 1.0) * 8;
  int i = std::min(7, int(s));
  double f = s - i;
  Rgb c;
  for (int k = 0; k < 3; ++k) c[k] = std::uint8_t(std::lround(anchors[i][k] * (1 - f) + anchors[i + 1][k] * f));
  return c;
}

void set_view(RenderOptions& options, const std::string& view) {
  if (view == "iso") options.azimuth = -60, options.elevation = 30;
  else if (view == "top") options.azimuth = 0, options.elevation = 90;  // map view: x right, y (north) up
  else if (view == "front") options.azimuth = -90, options.elevation = 0;
  else throw InputError(fmt::format("unknown view '{}' (iso, top or front)", view));
}

std::vector<double> named_vertex_field(const SurfaceMesh& mesh, const std::string& name) {
  std::vector<double> out;
  if (name == "phi") {
    out.resize(mesh.n_vertices());
    for (auto v : mesh.vertices()) out[v.idx()] = mesh.phi(v);
  } else if (name == "height") {
    out.resize(mesh.n_vertices());
    for (auto v : mesh.vertices()) out[v.idx()] = mesh.point(v)[2];
  } else if (name == "quality") {
    out.assign(mesh.n_vertices(), 0);
    std::vector<int> count(mesh.n_vertices(), 0);
    for (auto f : mesh.faces()) {
      double q = face_quality(mesh, f);
      for (auto v : mesh.fv_range(f)) out[v.idx()] += q, ++count[v.idx()];
    }
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = count[i] ? out[i] / count[i] : 0;
  }
  return out;
}

Image render(const SurfaceMesh& mesh, const RenderOptions& options) {
  if (options.width < 16 || options.height < 16) throw InputError("render: image size must be at least 16×16");
  const bool by_field = !options.field.empty();
  if (by_field && options.field.size() != mesh.n_vertices())
    throw InputError(fmt::format("render: field '{}' has {} values for {} vertices", options.field_name,
                                 options.field.size(), mesh.n_vertices()));
  Image image(options.width, options.height);
  const int bar_space = by_field && options.colorbar ? 110 : 0;
  const int plot_width = options.width - bar_space;

  // Camera frame: w towards the camera, u to the right, v up.
  const double az = options.azimuth * std::numbers::pi / 180, el = options.elevation * std::numbers::pi / 180;
  const Vec3 w(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  const Vec3 up = std::abs(w[2]) > 0.99 ? Vec3(-std::sin(az), std::cos(az), 0) : Vec3(0, 0, 1);
  const Vec3 u = cross(up, w).normalized();
  const Vec3 v = cross(w, u);
  const auto box = bounding_box(mesh);
  const Vec3 center = (box.min + box.max) * 0.5;
  const double radius = std::max(box.diagonal() / 2, 1e-300);
  const double distance = 3 * radius;
  // Fit the projected extent of the mesh (around the box centre) to the picture.
  double extent_u = 0, extent_v = 0;
  for (auto vh : mesh.vertices()) {
    Vec3 q = mesh.point(vh) - center;
    extent_u = std::max(extent_u, std::abs(dot(q, u))), extent_v = std::max(extent_v, std::abs(dot(q, v)));
  }
  double scale = 0.92 * std::min(plot_width, options.height) / (2 * radius);
  if (!options.perspective && extent_u > 0 && extent_v > 0)
    scale = 0.92 * std::min(plot_width / (2 * extent_u), options.height / (2 * extent_v));
  struct Projected {
    double x, y, depth;  // depth: larger is closer
  };
  auto project = [&](const Vec3& p) {
    Vec3 q = p - center;
    double x = dot(q, u), y = dot(q, v), z = dot(q, w);
    double s = scale;
    if (options.perspective) s = scale * distance / std::max(distance - z, 1e-9 * radius);
    return Projected{plot_width / 2.0 + s * x, options.height / 2.0 - s * y, z};
  };
  std::vector<Projected> screen(mesh.n_vertices());
  for (auto vh : mesh.vertices()) screen[vh.idx()] = project(mesh.point(vh));

  double lo = 0, hi = 1;
  if (by_field) {
    lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double f : options.field)
      if (std::isfinite(f)) lo = std::min(lo, f), hi = std::max(hi, f);
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-300) hi = lo + 1;
  }

  const Vec3 light = (w + 0.35 * u + 0.5 * v).normalized();
  std::vector<float> zbuffer(std::size_t(options.width) * options.height, -std::numeric_limits<float>::infinity());
  for (auto f : mesh.faces()) {
    auto vs = face_vertices(mesh, f);
    const Projected& a = screen[vs[0].idx()];
    const Projected& b = screen[vs[1].idx()];
    const Projected& c = screen[vs[2].idx()];
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (std::abs(area) < 1e-12) continue;
    const double intensity = 0.3 + 0.7 * std::abs(dot(face_normal(mesh, f), light));
    const Rgb flat = shade(mesh.inside(f) ? options.inside : options.outside, intensity);
    int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}))));
    int x1 = std::min(plot_width - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
    int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}))));
    int y1 = std::min(options.height - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
    for (int py = y0; py <= y1; ++py)
      for (int px = x0; px <= x1; ++px) {
        const double sx = px + 0.5, sy = py + 0.5;
        double l0 = ((b.x - sx) * (c.y - sy) - (b.y - sy) * (c.x - sx)) / area;
        double l1 = ((c.x - sx) * (a.y - sy) - (c.y - sy) * (a.x - sx)) / area;
        double l2 = 1 - l0 - l1;
        if (l0 < -1e-9 || l1 < -1e-9 || l2 < -1e-9) continue;
        float depth = float(l0 * a.depth + l1 * b.depth + l2 * c.depth);
        float& z = zbuffer[std::size_t(py) * options.width + px];
        if (depth <= z) continue;
        z = depth;
        if (by_field) {
          double value = l0 * options.field[vs[0].idx()] + l1 * options.field[vs[1].idx()] +
                         l2 * options.field[vs[2].idx()];
          image.set(px, py, shade(colormap((value - lo) / (hi - lo)), intensity));
        } else {
          image.set(px, py, flat);
        }
      }
  }

  if (options.draw_interface) {
    // Interface edges in front of the surface: depth-tested with a tolerance of a few pixels.
    const double tolerance = 3.0 / scale * std::max(1.0, options.interface_width);
    const double r = std::max(0.5, options.interface_width / 2);
    const int ir = int(std::ceil(r));
    for (auto e : mesh.edges()) {
      if (!mesh.interface(e)) continue;
      auto h = mesh.halfedge_handle(e, 0);
      const Projected& a = screen[mesh.from_vertex_handle(h).idx()];
      const Projected& b = screen[mesh.to_vertex_handle(h).idx()];
      const int steps = std::max(1, int(std::ceil(std::hypot(b.x - a.x, b.y - a.y) * 2)));
      for (int s = 0; s <= steps; ++s) {
        double t = double(s) / steps;
        double x = a.x + (b.x - a.x) * t, y = a.y + (b.y - a.y) * t, depth = a.depth + (b.depth - a.depth) * t;
        for (int dy = -ir; dy <= ir; ++dy)
          for (int dx = -ir; dx <= ir; ++dx) {
            int px = int(std::floor(x)) + dx, py = int(std::floor(y)) + dy;
            if (px < 0 || py < 0 || px >= plot_width || py >= options.height) continue;
            if ((px + 0.5 - x) * (px + 0.5 - x) + (py + 0.5 - y) * (py + 0.5 - y) > r * r) continue;
            if (depth + tolerance < zbuffer[std::size_t(py) * options.width + px]) continue;
            image.set(px, py, options.interface_color);
          }
      }
    }
  }

  const Rgb ink{20, 20, 20};
  if (by_field && options.colorbar) {
    const int x0 = plot_width + 20, x1 = x0 + 24;
    const int y0 = 40, y1 = options.height - 40;
    for (int y = y0; y < y1; ++y) image.fill_rect(x0, y, x1, y + 1, colormap(double(y1 - 1 - y) / std::max(1, y1 - y0 - 1)));
    image.line(x0, y0, x1, y0, ink), image.line(x0, y1, x1, y1, ink);
    image.line(x0, y0, x0, y1, ink), image.line(x1, y0, x1, y1, ink);
    image.text(x1 + 4, y0 - 3, format_value(hi), ink);
    image.text(x1 + 4, y1 - 4, format_value(lo), ink);
    image.text(std::max(0, x0 - 10), y0 - 20, options.field_name, ink);
  }
  if (!options.title.empty()) image.text(8, 8, options.title, ink, 2);
  return image;
}

void render_png(const SurfaceMesh& mesh, const std::filesystem::path& file, const RenderOptions& options) {
  write_png(render(mesh, options), file);
}

}  // namespace bodyfit
