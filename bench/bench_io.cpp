// Read and write times of every mesh format for a geodesic sphere (default 245 000 faces).
//
//   bench_io [faces] [out.csv] [directory]
//
// Prints one line per format and operation and writes them as CSV (format,operation,faces,seconds,bytes).
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
  using namespace bodyfit;
  namespace fs = std::filesystem;
  const std::size_t faces = argc > 1 ? std::stoul(argv[1]) : 245000;
  const std::string csv_path = argc > 2 ? argv[2] : "bench_io.csv";
  const fs::path dir = argc > 3 ? fs::path(argv[3]) : fs::temp_directory_path() / "bodyfit-bench-io";
  fs::create_directories(dir);

  auto mesh = make_sphere({.faces = faces});
  for (auto v : mesh.vertices()) mesh.phi(v) = mesh.point(v)[2];
  label_regions_from_phi(mesh);
  fmt::print("sphere: {} vertices, {} faces\n", mesh.n_vertices(), mesh.n_faces());

  std::ofstream csv(csv_path);
  csv << "format,operation,faces,seconds,bytes\n";
  auto time = [](auto&& f) {
    auto start = std::chrono::steady_clock::now();
    f();
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto report = [&](const std::string& format, const char* operation, double seconds, std::uintmax_t bytes) {
    fmt::print("{:>6} {:>5}: {:8.1f} ms  {:8.1f} MB\n", format, operation, 1e3 * seconds, bytes / 1e6);
    csv << format << ',' << operation << ',' << mesh.n_faces() << ',' << seconds << ',' << bytes << '\n';
  };
  for (const char* ext : {".mesh", ".meshb", ".vtu", ".obj", ".off", ".ply", ".stl"}) {
    const fs::path file = dir / (std::string("sphere") + ext);
    double w = time([&] { write_mesh(mesh, file); });
    report(ext + 1, "write", w, fs::file_size(file));
    if (std::string(ext) == ".vtu") continue;
    double r = time([&] { (void)read_mesh(file); });
    report(ext + 1, "read", r, fs::file_size(file));
  }
  ScalarField phi = mesh.phi_field();
  for (const char* ext : {".sol", ".solb"}) {
    const fs::path file = dir / (std::string("phi") + ext);
    double w = time([&] { write_scalar_sol(file, phi); });
    report(ext + 1, "write", w, fs::file_size(file));
    double r = time([&] { (void)read_scalar_sol(file, phi.size()); });
    report(ext + 1, "read", r, fs::file_size(file));
  }
  fs::remove_all(dir);
  return 0;
}
