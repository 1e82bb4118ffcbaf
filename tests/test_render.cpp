// PNG rendering and plots: size, and that the pixels show what was asked (both region colours,
// interface lines, a colorbar).
#include <bodyfit/error.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>
#include <bodyfit/app/plot.hpp>
#include <bodyfit/app/render.hpp>

#include "test_support.hpp"

#include <doctest/doctest.h>
#include <fmt/format.h>

#include <cmath>
#include <fstream>

using namespace bodyfit;

namespace {

/// A sphere whose faces with centroid z > 0.3 are inside G (interface edges tagged).
SurfaceMesh sphere_with_cap() {
  SurfaceMesh mesh = make_sphere({.faces = 2000});
  for (auto f : mesh.faces()) {
    Vec3 c(0, 0, 0);
    for (auto v : mesh.fv_range(f)) c += mesh.point(v) / 3;
    mesh.region(f) = c[2] > 0.3 ? kInside : kOutside;
  }
  update_interface_from_regions(mesh);
  return mesh;
}

/// Pixels whose hue is close to the shaded colour `c` (same channel ratios, any brightness).
std::size_t count_like(const Image& image, Rgb c) {
  std::size_t n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      Rgb p = image.at(x, y);
      if (p[0] == 255 && p[1] == 255 && p[2] == 255) continue;
      double scale = double(p[0] + p[1] + p[2]) / (c[0] + c[1] + c[2]);
      if (scale < 0.2) continue;
      bool close = true;
      for (int k = 0; k < 3; ++k) close = close && std::abs(p[k] - c[k] * scale) < 12;
      n += close;
    }
  return n;
}

std::size_t count_dark(const Image& image) {
  std::size_t n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      Rgb p = image.at(x, y);
      n += p[0] < 40 && p[1] < 40 && p[2] < 40;
    }
  return n;
}

}  // namespace

TEST_CASE("render writes a PNG of the requested size showing both regions and the interface") {
  test::TempDir dir("render");
  SurfaceMesh mesh = sphere_with_cap();
  RenderOptions options;
  options.width = 320, options.height = 240;
  render_png(mesh, dir / "cap.png", options);
  Image image = read_png(dir / "cap.png");
  CHECK(image.width == 320);
  CHECK(image.height == 240);
  const std::size_t inside = count_like(image, options.inside), outside = count_like(image, options.outside);
  CHECK(inside > 2000);
  CHECK(outside > 2000);
  CHECK(count_dark(image) > 100);  // the interface curve
  // The corners are background.
  CHECK(image.at(0, 0) == Rgb{255, 255, 255});

  // From the top, the cap (z > 0.3) is a disk in the middle of the picture.
  set_view(options, "top");
  Image top = render(mesh, options);
  Rgb centre = top.at(options.width / 2, options.height / 2);
  CHECK(centre[0] > centre[2]);  // inside colour: red dominates
  options.draw_interface = false;
  CHECK(count_dark(render(mesh, options)) == 0);
  CHECK_THROWS_AS(set_view(options, "sideways"), InputError);
}

TEST_CASE("render colours a field through the colormap with a colorbar") {
  SurfaceMesh mesh = sphere_with_cap();
  RenderOptions options;
  options.width = 400, options.height = 300;
  options.field = named_vertex_field(mesh, "height");
  options.field_name = "height";
  REQUIRE(options.field.size() == mesh.n_vertices());
  Image image = render(mesh, options);
  // The colorbar: its top is the colormap's top colour, its bottom the bottom colour.
  const int bar_x = options.width - 110 + 20 + 12;
  auto near = [](Rgb a, Rgb b) { return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) < 8; };
  Rgb top = image.at(bar_x, 45), bottom = image.at(bar_x, options.height - 45);
  CHECK(top[0] > 150);  // yellow end of the map
  CHECK(top[1] > 150);
  CHECK(top[2] < 120);
  CHECK(bottom[2] > bottom[1]);  // purple end
  CHECK(near(image.at(bar_x, options.height - 42), colormap(0.0)));
  CHECK(!near(image.at(bar_x, options.height / 2), colormap(0.0)));
  // Seen from the front, high points (top of the image) are yellow-ish, low points purple-ish.
  set_view(options, "front");
  options.draw_interface = false;
  image = render(mesh, options);
  // (the picture fits the bounding box's sphere of radius √3: the unit sphere spans ±77 pixels)
  Rgb high = image.at((options.width - 110) / 2, options.height / 2 - 50);
  Rgb low = image.at((options.width - 110) / 2, options.height / 2 + 50);
  CHECK(high[1] > low[1]);
  CHECK(low[2] > low[1]);
  options.field.pop_back();
  CHECK_THROWS_AS(render(mesh, options), InputError);
}

TEST_CASE("plot writes a log-log PNG of the requested size") {
  test::TempDir dir("plot");
  PlotSeries a{.label = "c = 0.5", .x = {0.1, 0.05, 0.025}, .y = {2.6e-2, 1.3e-2, 5.5e-3}, .color = series_color(0)};
  PlotSeries b{.label = "slope 1", .x = {0.1, 0.025}, .y = {2e-2, 5e-3}, .color = series_color(1), .markers = false,
               .dashed = true};
  PlotOptions options{.width = 640, .height = 480, .title = "E", .x_label = "h", .y_label = "E", .log_x = true,
                      .log_y = true};
  plot_png(dir / "plot.png", {a, b}, options);
  Image image = read_png(dir / "plot.png");
  CHECK(image.width == 640);
  CHECK(image.height == 480);
  CHECK(count_like(image, series_color(0)) > 50);
  CHECK(count_like(image, series_color(1)) > 50);
}

TEST_CASE("bodyfit render: CLI writes the PNG at --size") {
  test::TempDir dir("render-cli");
  write_mesh(sphere_with_cap(), dir / "cap.mesh");
  auto r = test::run_bodyfit("render " + (dir / "cap.mesh").string() + " -o " + (dir / "cap.png").string() +
                             " --size 300x200 --view front");
  REQUIRE_MESSAGE(r.exit_code == 0, r.output);
  Image image = read_png(dir / "cap.png");
  CHECK(image.width == 300);
  CHECK(image.height == 200);
  CHECK(count_like(image, RenderOptions{}.inside) > 1000);
  CHECK(count_like(image, RenderOptions{}.outside) > 1000);
  r = test::run_bodyfit("render " + (dir / "cap.mesh").string() + " -o " + (dir / "q.png").string() +
                        " --field quality --size 300x200");
  CHECK_MESSAGE(r.exit_code == 0, r.output);
  r = test::run_bodyfit("render " + (dir / "cap.mesh").string() + " -o " + (dir / "x.png").string() + " --size 30");
  CHECK(r.exit_code == 1);
  CHECK(r.output.find("--size '30'") != std::string::npos);
}

TEST_CASE("bodyfit render and info read the VTU files a run writes, with their fields") {
  test::TempDir dir("render-vtu");
  const SurfaceMesh mesh = sphere_with_cap();
  VtuFields fields;
  ScalarField height(mesh.n_vertices());
  for (auto v : mesh.vertices()) height[v.idx()] = mesh.point(v)[2];
  fields.point_scalars.emplace_back("speed", height);
  write_vtu(mesh, dir / "step.vtu", fields);
  auto r = test::run_bodyfit("render " + (dir / "step.vtu").string() + " -o " + (dir / "speed.png").string() +
                             " --field speed --size 300x200");
  REQUIRE_MESSAGE(r.exit_code == 0, r.output);
  CHECK(read_png(dir / "speed.png").width == 300);
  r = test::run_bodyfit("render " + (dir / "step.vtu").string() + " -o " + (dir / "x.png").string() + " --field sped");
  CHECK(r.exit_code == 1);
  CHECK(r.output.find("a field of the VTU (phi, speed)") != std::string::npos);
  r = test::run_bodyfit("info " + (dir / "step.vtu").string() + " --json");
  REQUIRE_MESSAGE(r.exit_code == 0, r.output);
  CHECK(r.output.find(fmt::format("\"faces\": {}", mesh.n_faces())) != std::string::npos);
}

TEST_CASE("the top view is a map: x (east) to the right, y (north) up") {
  SurfaceMesh plane = test::grid_square(20);  // [0, 1]², z = 0
  for (auto f : plane.faces()) {
    Vec3 c(0, 0, 0);
    for (auto v : plane.fv_range(f)) c += plane.point(v) / 3;
    plane.region(f) = c[0] > 0.5 && c[1] > 0.5 ? kInside : kOutside;  // the north-east quarter
  }
  update_interface_from_regions(plane);
  RenderOptions options;
  options.width = options.height = 200;
  options.draw_interface = false;
  set_view(options, "top");
  Image image = render(plane, options);
  auto is_inside = [&](int x, int y) {
    Rgb p = image.at(x, y);
    return p[0] > p[2];  // the inside colour is red-dominant, the outside blue-dominant
  };
  CHECK(is_inside(150, 50));    // upper right: north-east
  CHECK(!is_inside(50, 50));    // upper left: north-west
  CHECK(!is_inside(150, 150));  // lower right: south-east
  CHECK(!is_inside(50, 150));   // lower left: south-west
}

TEST_CASE("bodyfit plot: columns of a history to a PNG, an unknown column names the known ones") {
  bodyfit::test::TempDir dir("plot_command");
  std::ofstream(dir / "history.csv") << "iteration,time,J\n0,0,nan\n1,0.1,2.5\n2,0.2,1.5\n3,0.3,1.25\n";
  auto ok = bodyfit::test::run_bodyfit("plot " + (dir / "history.csv").string() + " -y J -y time -o " +
                                       (dir / "J.png").string() + " --title J");
  REQUIRE_MESSAGE(ok.exit_code == 0, ok.output);
  CHECK(std::filesystem::file_size(dir / "J.png") > 1000);
  auto bad = bodyfit::test::run_bodyfit("plot " + (dir / "history.csv").string() + " -y K -o " + (dir / "K.png").string());
  CHECK(bad.exit_code == 1);
  CHECK(bad.output.find("no column 'K' (columns: iteration, time, J)") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "K.png"));
}
