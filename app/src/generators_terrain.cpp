// Terrains: a procedural landscape (fractal sum of seeded gradient noise) or a DEM raster, meshed
// over a rectangle with a triangular lattice whose rows are shifted by half a step, so the triangles
// are near-equilateral in plan view and the four sides are straight rows/columns of vertices. Over a
// DEM with NODATA cells the lattice keeps the triangles over valid data only (then: one fan per
// vertex, no small islands), so the surface's boundary follows the data mask.
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/geometry.hpp>
#include <bodyfit/guards.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

namespace bodyfit {
namespace {

constexpr int kOctaves = 6;             // wavelengths feature_size … feature_size / 32
constexpr double kNoiseBound = 0.7072;  // |2-D gradient noise| ≤ √2/2 with unit gradients
constexpr double kContrast = 5.0;       // steepness of the smooth map of the noise onto [0, max]
constexpr double kMaxVertices = 2e7;

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double unit_from_hash(std::uint64_t h) { return double(h >> 11) * 0x1.0p-53; }

// Unit gradient at lattice node (ix, iy) of one octave.
void gradient(std::int64_t ix, std::int64_t iy, std::uint64_t octave_seed, double& gx, double& gy) {
  std::uint64_t h = splitmix64(octave_seed ^ splitmix64(std::uint64_t(ix) * 0x632be59bd9b4e019ULL ^
                                                        splitmix64(std::uint64_t(iy))));
  double angle = 2 * M_PI * unit_from_hash(h);
  gx = std::cos(angle), gy = std::sin(angle);
}

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }  // C² quintic

// Gradient noise in [−kNoiseBound, kNoiseBound], smooth (C²), zero at the lattice nodes.
double gradient_noise(double x, double y, std::uint64_t octave_seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = std::int64_t(fx), iy = std::int64_t(fy);
  const double u = x - fx, v = y - fy;
  double corner[2][2];
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      double gx, gy;
      gradient(ix + a, iy + b, octave_seed, gx, gy);
      corner[a][b] = gx * (u - a) + gy * (v - b);
    }
  const double su = fade(u), sv = fade(v);
  const double bottom = corner[0][0] + su * (corner[1][0] - corner[0][0]);
  const double top = corner[0][1] + su * (corner[1][1] - corner[0][1]);
  return bottom + sv * (top - bottom);
}

void check_terrain_options(const TerrainOptions& o) {
  auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(o.extent)) throw InputError("terrain: --extent must be positive");
  if (!positive(o.h) || o.h > o.extent) throw InputError("terrain: --h must be positive and at most the extent");
  if (!std::isfinite(o.max_height) || o.max_height < 0) throw InputError("terrain: --max-height must be ≥ 0");
  if (!positive(o.feature_size)) throw InputError("terrain: the feature size must be positive");
}

// Triangular lattice over [x0, x1] × [y0, y1] with edge ≈ h. Even rows hold nx + 1 vertices at
// x0 + i·dx; odd rows are shifted by dx/2 and closed by extra vertices on the two sides. Faces are
// counter-clockwise in plan view, so normals point up (+z).
SurfaceMesh lattice_mesh(double x0, double x1, double y0, double y1, double h,
                         const std::function<double(double, double)>& height) {
  const double row_height = h * std::sqrt(3.0) / 2;
  check_face_budget(2 * std::max(1.0, (x1 - x0) / h) * std::max(1.0, (y1 - y0) / row_height),
                    fmt::format("terrain of {} × {} at edge length {}", x1 - x0, y1 - y0, h));
  const long nx = std::max(1L, std::lround((x1 - x0) / h));
  const long ny = std::max(1L, std::lround((y1 - y0) / row_height));
  if (double(nx + 2) * double(ny + 1) > kMaxVertices)
    throw InputError(fmt::format("terrain: {}×{} rows of vertices is too many; use a larger --h", nx + 2, ny + 1));
  const double dx = (x1 - x0) / double(nx), dy = (y1 - y0) / double(ny);

  SurfaceMesh mesh;
  std::vector<std::vector<VertexHandle>> rows(std::size_t(ny) + 1);
  for (long j = 0; j <= ny; ++j) {
    const double y = j == ny ? y1 : y0 + double(j) * dy;
    std::vector<double> xs;
    if (j % 2 == 0) {
      for (long i = 0; i <= nx; ++i) xs.push_back(i == nx ? x1 : x0 + double(i) * dx);
    } else {
      xs.push_back(x0);
      for (long i = 0; i < nx; ++i) xs.push_back(x0 + (double(i) + 0.5) * dx);
      xs.push_back(x1);
    }
    for (double x : xs) rows[std::size_t(j)].push_back(mesh.add_vertex(Vec3(x, y, height(x, y))));
  }
  for (long j = 0; j < ny; ++j) {
    const auto& lo = rows[std::size_t(j)];
    const auto& hi = rows[std::size_t(j) + 1];
    const auto n = std::size_t(nx);
    if (j % 2 == 0) {  // even row below (n + 1 vertices), odd row above (n + 2)
      mesh.add_face(lo[0], hi[1], hi[0]);
      for (std::size_t i = 0; i < n; ++i) mesh.add_face(lo[i], lo[i + 1], hi[i + 1]);
      for (std::size_t i = 1; i < n; ++i) mesh.add_face(lo[i], hi[i + 1], hi[i]);
      mesh.add_face(lo[n], hi[n + 1], hi[n]);
    } else {  // odd row below, even row above
      mesh.add_face(lo[0], lo[1], hi[0]);
      for (std::size_t i = 0; i + 1 < n; ++i) mesh.add_face(lo[i + 1], lo[i + 2], hi[i + 1]);
      for (std::size_t i = 0; i < n; ++i) mesh.add_face(hi[i], lo[i + 1], hi[i + 1]);
      mesh.add_face(lo[n], lo[n + 1], hi[n]);
    }
  }
  for (auto f : mesh.faces()) mesh.region(f) = kOutside;
  for (auto v : {rows.front().front(), rows.front().back(), rows.back().front(), rows.back().back()})
    mesh.corner(v) = 1;
  return mesh;
}

// Whether (x, y) lies in a valid cell of the grid, cells taken as closed squares (a point on the
// side shared with a NODATA cell is over data). The tolerance absorbs the rounding of lattice
// coordinates that fall on cell sides.
bool over_valid_data(const HeightGrid& grid, double x, double y) {
  constexpr double kSide = 1e-9;  // in cells
  const double u = (x - grid.x_origin) / grid.cell_size, v = (y - grid.y_origin) / grid.cell_size;
  auto candidates = [&](double t, long n, std::array<long, 2>& out) {
    const long base = long(std::floor(t));
    const double frac = t - double(base);
    out = {base, base};
    if (frac < kSide) out[1] = base - 1;
    else if (frac > 1 - kSide) out[1] = base + 1;
    for (long& k : out)
      if (k < 0 || k >= n) k = -1;
  };
  std::array<long, 2> cols, souths;
  candidates(u, long(grid.cols), cols);
  candidates(v, long(grid.rows), souths);
  for (long c : cols)
    for (long s : souths)
      if (c >= 0 && s >= 0 && grid.valid(grid.rows - 1 - std::size_t(s), std::size_t(c))) return true;
  return false;
}

// A triangle is over valid data when its vertices, edge midpoints and centroid are: every point of
// it is then within 0.29 of its longest edge of valid data, and a NODATA strip wider than that
// (in plan view) cuts it out.
bool face_over_valid_data(const HeightGrid& grid, const std::array<Vec3, 3>& p) {
  const std::array<Vec3, 7> samples{p[0], p[1], p[2], 0.5 * (p[0] + p[1]), 0.5 * (p[1] + p[2]), 0.5 * (p[2] + p[0]),
                                    (p[0] + p[1] + p[2]) / 3.0};
  return std::all_of(samples.begin(), samples.end(), [&](const Vec3& q) { return over_valid_data(grid, q[0], q[1]); });
}

// Where several fans of kept faces meet at a vertex (the mask touches itself at a point), keep the
// largest fan (the first of equal ones, in the vertex's order) and drop the others, until every
// vertex has one fan. Returns the faces dropped.
std::size_t keep_one_fan_per_vertex(const SurfaceMesh& mesh, std::vector<char>& keep) {
  std::size_t dropped = 0;
  std::vector<FaceHandle> ring;
  for (bool changed = true; changed;) {
    changed = false;
    for (auto v : mesh.vertices()) {
      ring.clear();
      for (auto h : mesh.voh_range(v)) ring.push_back(mesh.face_handle(h));  // invalid: the lattice's outside
      auto kept = [&](std::size_t i) { return ring[i].is_valid() && keep[std::size_t(ring[i].idx())]; };
      const std::size_t n = ring.size();
      // Runs of kept faces, cyclically: each starts where a kept face follows one that is not.
      std::vector<std::pair<std::size_t, std::size_t>> runs;  // (start, length)
      for (std::size_t i = 0; i < n; ++i) {
        if (!kept(i) || kept((i + n - 1) % n)) continue;
        std::size_t length = 0;
        while (length < n && kept((i + length) % n)) ++length;
        runs.emplace_back(i, length);
      }
      if (runs.size() < 2) continue;
      std::size_t largest = 0;
      for (std::size_t r = 1; r < runs.size(); ++r)
        if (runs[r].second > runs[largest].second) largest = r;
      for (std::size_t r = 0; r < runs.size(); ++r) {
        if (r == largest) continue;
        for (std::size_t k = 0; k < runs[r].second; ++k) keep[std::size_t(ring[(runs[r].first + k) % n].idx())] = 0;
        dropped += runs[r].second;
      }
      changed = true;
    }
  }
  return dropped;
}

double plan_area(const std::array<Vec3, 3>& p) {
  return 0.5 * std::abs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]));
}

// Drops the connected pieces (through edges) of kept faces whose plan-view area is below
// `min_area`. Returns the number of pieces dropped.
std::size_t drop_small_islands(const SurfaceMesh& mesh, std::vector<char>& keep, double min_area) {
  std::vector<int> piece(mesh.n_faces(), -1);
  std::vector<FaceHandle> stack, members;
  std::size_t dropped = 0;
  int pieces = 0;
  for (auto seed : mesh.faces()) {
    if (!keep[std::size_t(seed.idx())] || piece[std::size_t(seed.idx())] >= 0) continue;
    members.clear();
    stack.assign(1, seed);
    piece[std::size_t(seed.idx())] = pieces;
    double area = 0;
    while (!stack.empty()) {
      const FaceHandle f = stack.back();
      stack.pop_back();
      members.push_back(f);
      area += plan_area(face_points(mesh, f));
      for (auto g : mesh.ff_range(f))
        if (keep[std::size_t(g.idx())] && piece[std::size_t(g.idx())] < 0) {
          piece[std::size_t(g.idx())] = pieces;
          stack.push_back(g);
        }
    }
    ++pieces;
    if (area >= min_area) continue;
    for (auto f : members) keep[std::size_t(f.idx())] = 0;
    ++dropped;
  }
  return dropped;
}

// Keeps the lattice's triangles over valid data (see make_terrain_from_grid) and logs what was left out.
void keep_valid_data(SurfaceMesh& mesh, const HeightGrid& grid, double h, double min_island_area) {
  std::vector<char> keep(mesh.n_faces(), 0);
  for (auto f : mesh.faces()) keep[std::size_t(f.idx())] = face_over_valid_data(grid, face_points(mesh, f));
  const std::size_t pinched = keep_one_fan_per_vertex(mesh, keep);
  const double min_area = min_island_area >= 0 ? min_island_area : 16 * h * h;
  const std::size_t islands = drop_small_islands(mesh, keep, min_area);
  if (std::find(keep.begin(), keep.end(), char(1)) == keep.end())
    throw InputError(fmt::format("terrain: no piece of the DEM's valid data is {} m² or more at edge length {} m "
                                 "(use a smaller h)",
                                 min_area, h));
  for (auto f : mesh.faces())
    if (!keep[std::size_t(f.idx())]) mesh.delete_face(f, true);
  mesh.garbage_collection();
  spdlog::info("terrain: {} NODATA cell(s) of {} left out, the surface covers the valid cells only ({} triangles "
               "dropped where pieces touched at a vertex, {} island(s) under {:.4g} m² dropped)",
               count_nodata(grid), grid.heights.size(), pinched, islands, min_area);
}

}  // namespace

double terrain_height(const TerrainOptions& options, double x, double y) {
  double sum = 0, amplitude_sum = 0, amplitude = 1, frequency = 1 / options.feature_size;
  for (int k = 0; k < kOctaves; ++k) {
    const std::uint64_t octave_seed = splitmix64(options.seed * 0x9e3779b97f4a7c15ULL + std::uint64_t(k));
    // Each octave is shifted by a seeded offset so their lattices do not line up.
    const double ox = 1000 * unit_from_hash(splitmix64(octave_seed + 1));
    const double oy = 1000 * unit_from_hash(splitmix64(octave_seed + 2));
    sum += amplitude * gradient_noise(x * frequency + ox, y * frequency + oy, octave_seed) / kNoiseBound;
    amplitude_sum += amplitude;
    amplitude *= 0.5;
    frequency *= 2;
  }
  const double n = std::clamp(sum / amplitude_sum, -1.0, 1.0);  // in [−1, 1] by construction
  // Smooth increasing map of [−1, 1] onto [0, 1] that stretches the common middle values.
  const double shaped = 0.5 + 0.5 * std::tanh(kContrast * 0.5 * n) / std::tanh(kContrast * 0.5);
  return options.max_height * std::clamp(shaped, 0.0, 1.0);
}

SurfaceMesh make_terrain(const TerrainOptions& options) {
  check_terrain_options(options);
  return lattice_mesh(0, options.extent, 0, options.extent, options.h,
                      [&](double x, double y) { return terrain_height(options, x, y); });
}

SurfaceMesh make_terrain_from_grid(const HeightGrid& grid, const GridTerrainOptions& options) {
  if (grid.cols == 0 || grid.rows == 0 || grid.heights.size() != grid.cols * grid.rows)
    throw InputError("terrain: the height grid is empty or inconsistent");
  if (!(grid.cell_size > 0)) throw InputError("terrain: the height grid's cell size must be positive");
  const double h = options.h == 0 ? grid.cell_size : options.h;
  const double width = double(grid.cols) * grid.cell_size, height = double(grid.rows) * grid.cell_size;
  if (!(h > 0) || !std::isfinite(h) || h > std::max(width, height))
    throw InputError("terrain: --h must be positive and at most the DEM's extent");
  const std::size_t missing = count_nodata(grid);
  if (missing == grid.heights.size()) throw InputError("terrain: every cell of the DEM is NODATA");
  const bool fill = options.nodata == NodataMode::fill && missing > 0;
  HeightGrid filled;
  if (fill) {
    filled = grid;
    fill_nodata(filled);
    spdlog::warn("terrain: {} NODATA cell(s) of {} filled with the nearest valid height (nodata = \"fill\")", missing,
                 grid.heights.size());
  }
  const HeightGrid& heights = fill ? filled : grid;
  SurfaceMesh mesh = lattice_mesh(grid.x_origin, grid.x_origin + width, grid.y_origin, grid.y_origin + height, h,
                                  [&](double x, double y) { return heights.sample(x, y); });
  if (missing > 0 && !fill) keep_valid_data(mesh, grid, h, options.min_island_area);
  return mesh;
}

SurfaceMesh make_terrain_from_grid(const HeightGrid& grid, double h) {
  return make_terrain_from_grid(grid, GridTerrainOptions{.h = h});
}

}  // namespace bodyfit
