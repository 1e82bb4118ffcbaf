#pragma once
// Software rendering of a surface mesh to PNG, with no external viewer: z-buffered triangles with
// two-sided Lambert shading, coloured by region or by a scalar field through a colormap (with a
// colorbar), interface edges drawn as dark lines. Used for the run's snapshots and `bodyfit render`.
#include <bodyfit/mesh.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace bodyfit {

using Rgb = std::array<std::uint8_t, 3>;

/// An 8-bit RGB raster, row 0 at the top.
struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  ///< width·height·3
  Image() = default;
  Image(int w, int h, Rgb background = {255, 255, 255});
  Rgb at(int x, int y) const;
  void set(int x, int y, Rgb c);
  /// Thick line and filled rectangle, clipped to the image.
  void line(double x0, double y0, double x1, double y1, Rgb c, double width = 1);
  void fill_rect(int x0, int y0, int x1, int y1, Rgb c);
  /// Text in a built-in 5×7 pixel font (digits, letters, common signs), `scale` pixels per dot;
  /// (x, y) is the top-left corner. Returns the width drawn.
  int text(int x, int y, const std::string& s, Rgb c, int scale = 1);
  static int text_width(const std::string& s, int scale = 1);
};

/// Write an image as an 8-bit RGB PNG (atomically).
void write_png(const Image& image, const std::filesystem::path& file);
/// Read an 8-bit RGB or RGBA PNG (for tests and tools).
Image read_png(const std::filesystem::path& file);

/// A colour of the viridis-like map at s ∈ [0, 1].
Rgb colormap(double s);

struct RenderOptions {
  int width = 800, height = 600;
  /// Camera direction: azimuth around +z from +x and elevation above the xy plane, in degrees
  /// (the camera looks at the centre of the bounding box from that direction).
  double azimuth = -60, elevation = 30;
  bool perspective = false;        ///< orthographic by default
  /// Colour by region (empty `field`) or by the scalar field (one value per vertex).
  std::vector<double> field;
  std::string field_name;          ///< shown above the colorbar
  Rgb inside{220, 90, 40};         ///< G
  Rgb outside{150, 175, 205};      ///< S \ G
  Rgb interface_color{20, 20, 20};
  bool draw_interface = true;
  double interface_width = 2;      ///< pixels
  bool colorbar = true;            ///< when colouring by a field
  std::string title;               ///< drawn in the top-left corner when not empty
};

/// Set azimuth/elevation for a named view: "iso", "top" or "front" (InputError otherwise).
void set_view(RenderOptions& options, const std::string& view);

/// A vertex field by name: "phi" (v:phi), "quality" (mean quality of the incident faces),
/// "height" (z); empty for "region" and for an unknown name.
std::vector<double> named_vertex_field(const SurfaceMesh& mesh, const std::string& name);

Image render(const SurfaceMesh& mesh, const RenderOptions& options = {});
void render_png(const SurfaceMesh& mesh, const std::filesystem::path& file, const RenderOptions& options = {});

}  // namespace bodyfit
