// bodyfit mesh sphere|terrain: mesh generators.
#include "commands.hpp"
#include "validators.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/io.hpp>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>
#include <memory>

namespace {

void report(const char* what, const bodyfit::SurfaceMesh& mesh, const std::string& output) {
  auto q = bodyfit::quality_stats(mesh);
  auto e = bodyfit::edge_length_stats(mesh);
  spdlog::info("{}: {} vertices, {} faces, quality min {:.3f} mean {:.3f}, edges {:.4g}..{:.4g} (mean {:.4g}) -> {}",
               what, mesh.n_vertices(), mesh.n_faces(), q.min, q.mean, e.min, e.max, e.mean, output);
}

bodyfit::cli::Command setup_mesh(CLI::App& app) {
  auto* cmd = app.add_subcommand("mesh", "generate a surface mesh (geodesic sphere, terrain)");
  cmd->require_subcommand(1);
  auto sphere = std::make_shared<bodyfit::SphereOptions>();
  auto terrain = std::make_shared<bodyfit::TerrainOptions>();
  auto output = std::make_shared<std::string>();
  auto dem = std::make_shared<std::string>();
  const char* formats = "output mesh (.mesh, .meshb, .obj, .off, .ply, .stl, .vtu)";

  auto* sph = cmd->add_subcommand("sphere", "geodesic sphere: near-equilateral triangles, vertices exactly on the sphere");
  sph->add_option("--faces", sphere->faces, "target number of triangles, ≥ 20 (result within ±10 %)")->capture_default_str();
  sph->add_option("--radius", sphere->radius, "radius")->capture_default_str()->check(bodyfit::cli::finite_above(0));
  sph->add_option("-o,--output", *output, formats)->required();

  auto* ter = cmd->add_subcommand(
      "terrain",
      "terrain over a square (procedural, seeded) or over a DEM's extent: near-equilateral triangles of edge ≈ h, "
      "straight sides, normals up. Coordinates in metres.");
  ter->add_option("--extent", terrain->extent, "side of the square domain [0, extent]² (procedural)")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_above(0));
  auto* h_option = ter->add_option("--h", terrain->h, "target edge length (with --dem: default the cell size)")
                       ->capture_default_str()
                       ->check(bodyfit::cli::finite_above(0));
  ter->add_option("--seed", terrain->seed, "the landscape is a deterministic function of the seed")->capture_default_str();
  ter->add_option("--max-height", terrain->max_height, "heights lie in [0, max-height] (procedural)")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_at_least(0));
  ter->add_option("--feature-size", terrain->feature_size, "horizontal scale of the largest hills (procedural)")
      ->capture_default_str()
      ->check(bodyfit::cli::finite_above(0));
  auto* dem_option = ter->add_option("--dem", *dem, "DEM raster: ESRI ASCII grid .asc or GeoTIFF .tif; heights by bilinear interpolation");
  auto nodata = std::make_shared<std::string>("hole");
  ter->add_option("--nodata", *nodata,
                  "with --dem: NODATA cells are holes (the surface covers the valid cells only, its boundary follows "
                  "the data) or are filled with the nearest valid height")
      ->capture_default_str()
      ->check(CLI::IsMember({"hole", "fill"}))
      ->needs(dem_option);
  auto reproject = std::make_shared<std::string>("none");
  ter->add_option("--reproject", *reproject,
                  "with --dem: a raster in degrees (geographic coordinate system) is refused (none) or warped to the "
                  "WGS 84 / UTM zone of its centre (utm; bilinear, NODATA kept)")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "utm"}))
      ->needs(dem_option);
  ter->add_option("-o,--output", *output, formats)->required();

  return {cmd, [=]() {
            if (sph->parsed()) {
              auto mesh = bodyfit::make_sphere(*sphere);
              bodyfit::write_mesh(mesh, *output);
              report("sphere", mesh, *output);
            } else if (ter->parsed()) {
              bodyfit::SurfaceMesh mesh;
              if (!dem->empty()) {
                const bodyfit::DemReadOptions read{
                    .reproject = *reproject == "utm" ? bodyfit::Reprojection::utm : bodyfit::Reprojection::none};
                auto grid = bodyfit::read_dem(*dem, read);
                double lo = std::numeric_limits<double>::infinity(), hi = -lo;
                for (std::size_t r = 0; r < grid.rows; ++r)
                  for (std::size_t c = 0; c < grid.cols; ++c)
                    if (grid.valid(r, c)) lo = std::min(lo, grid.at(r, c)), hi = std::max(hi, grid.at(r, c));
                spdlog::info("DEM {}: {} × {} cells of {} m, heights {:.6g}..{:.6g} ({} NODATA)", *dem, grid.cols,
                             grid.rows, grid.cell_size, lo, hi, bodyfit::count_nodata(grid));
                mesh = bodyfit::make_terrain_from_grid(
                    grid, {.h = h_option->count() ? terrain->h : 0.0,
                           .nodata = *nodata == "fill" ? bodyfit::NodataMode::fill : bodyfit::NodataMode::hole});
              } else {
                mesh = bodyfit::make_terrain(*terrain);
              }
              bodyfit::write_mesh(mesh, *output);
              report("terrain", mesh, *output);
            }
            return 0;
          },
          /*on_huge_pages=*/true};
}

BODYFIT_COMMAND(10, setup_mesh);

}  // namespace
