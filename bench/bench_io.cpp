// Read and write speeds of every mesh format for a geodesic sphere (default 245 000 faces).
//
//   bench_io [--faces N] [--repeat R] [--csv FILE] [--dir DIR] [--medit-only]
//
// Each operation is timed R times (default 5) and its median printed in ms and MB/s (file bytes
// per second), then written as CSV (format,operation,faces,seconds,bytes,mb_per_s). For Medit
// files, besides `read` (parse + validated build of the mesh, in this warm process, whose heap
// keeps freed blocks as every bodyfit process does) and `write`:
//   parse   the parse alone (the records, before the mesh is built);
//   cold    a read in a fresh process, as `bodyfit <command> in.mesh` does it: restarted once
//           with its heap on transparent huge pages and freed blocks kept, as the commands are,
//           memory never touched before (page faults included).
#include "bench_args.hpp"

#include <bodyfit/app/huge_page_heap.hpp>
#include <bodyfit/generators.hpp>
#include <bodyfit/io.hpp>

#include "../core/src/io_internal.hpp"  // the parse alone (io_detail::parse_medit)

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace {

namespace fs = std::filesystem;
using namespace bodyfit;

const char* kUsage = R"(usage: bench_io [--faces N] [--repeat R] [--csv FILE] [--dir DIR] [--medit-only]

Times writing and reading a geodesic sphere in every mesh format (median of R runs).
  --faces N      faces of the sphere (default 245000)
  --repeat R     runs per operation (default 5)
  --csv FILE     CSV output (default bench_io.csv)
  --dir DIR      where to make the scratch directory (default the system's temporary directory;
                 the scratch directory, bench_io-<pid>, is removed at the end)
  --medit-only   only .mesh, .meshb, .sol and .solb
  --help         this text
Operations: write, read (parse + validated build), parse (Medit: the parse alone), cold (Medit: a
read in a fresh process, as the bodyfit commands do it).
)";

struct Arguments {
  std::size_t faces = 245000;
  int repeat = 5;
  std::string csv = "bench_io.csv";
  fs::path dir = fs::temp_directory_path();
  bool medit_only = false;
  std::string read_once;  // internal: read this file and print the seconds (the "cold" child)
};

Arguments parse_arguments(int argc, char** argv) {
  Arguments a;
  bench::Arguments parser("bench_io", kUsage);
  parser.option("--faces", a.faces);
  parser.option("--repeat", a.repeat);
  parser.option("--csv", a.csv);
  parser.option("--dir", a.dir);
  parser.flag("--medit-only", a.medit_only);
  parser.option("--read-once", a.read_once);
  parser.parse(argc, argv);
  if (a.faces < 20) parser.fail("--faces: expected at least 20");
  if (a.repeat < 1) parser.fail("--repeat: expected at least 1");
  return a;
}

double seconds_of(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Seconds of one read_mesh in a fresh process (this executable with --read-once).
double cold_read(const fs::path& file) {
  const fs::path out = file.string() + ".seconds";
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  const std::string file_arg = file.string();
  const std::string redirect = out.string();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, redirect.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> args = {const_cast<char*>(self.c_str()), const_cast<char*>("--read-once"),
                             const_cast<char*>(file_arg.c_str()), nullptr};
  pid_t pid = 0;
  const int failed = posix_spawn(&pid, self.c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  if (failed || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  double seconds = -1;
  std::ifstream(out) >> seconds;
  fs::remove(out);
  return seconds;
}

/// Writes the file's dirty pages out and waits, so that no writeback of the file just written
/// runs during the reads that follow (on one of the cores they run on).
void flush_to_disk(const fs::path& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

int main(int argc, char** argv) {
  const Arguments args = parse_arguments(argc, argv);
  keep_freed_blocks();  // as every bodyfit process does from its start
  if (!args.read_once.empty()) {
    restart_on_huge_pages(argv);  // the heap as the stage commands have it
    const double s = seconds_of([&] { (void)read_mesh(args.read_once); });
    std::printf("%.9f\n", s);
    return 0;
  }
  const fs::path scratch = args.dir / fmt::format("bench_io-{}", ::getpid());
  fs::create_directories(scratch);
  auto mesh = make_sphere({.faces = args.faces});
  for (auto v : mesh.vertices()) mesh.phi(v) = mesh.point(v)[2];
  label_regions_from_phi(mesh);
  fmt::print("sphere: {} vertices, {} faces; median of {} runs\n", mesh.n_vertices(), mesh.n_faces(), args.repeat);

  std::ofstream csv(args.csv);
  csv << "format,operation,faces,seconds,bytes,mb_per_s\n";
  auto report = [&](const std::string& format, const char* operation, const std::vector<double>& runs,
                    std::uintmax_t bytes) {
    const double s = median(runs);
    const double rate = bytes / 1e6 / s;
    fmt::print("{:>6} {:>5}: {:8.1f} ms  {:7.1f} MB  {:7.0f} MB/s\n", format, operation, 1e3 * s, bytes / 1e6, rate);
    csv << format << ',' << operation << ',' << mesh.n_faces() << ',' << s << ',' << bytes << ',' << rate << '\n';
  };
  auto repeat = [&](const std::function<void()>& f) {
    std::vector<double> runs;
    for (int i = 0; i < args.repeat; ++i) runs.push_back(seconds_of(f));
    return runs;
  };

  std::vector<const char*> mesh_formats = {".mesh", ".meshb"};
  if (!args.medit_only)
    for (const char* ext : {".vtu", ".obj", ".off", ".ply", ".stl"}) mesh_formats.push_back(ext);
  for (const char* ext : mesh_formats) {
    const std::string format = ext + 1;
    const fs::path file = scratch / (std::string("sphere") + ext);
    auto runs = repeat([&] { write_mesh(mesh, file); });
    const auto bytes = fs::file_size(file);
    report(format, "write", runs, bytes);
    flush_to_disk(file);  // not timed
    if (format == "vtu") continue;
    report(format, "read", repeat([&] { (void)read_mesh(file); }), bytes);
    if (format != "mesh" && format != "meshb") continue;
    const io_detail::FileBytes content(file);
    report(format, "parse", repeat([&] { (void)io_detail::parse_medit(content.view(), file); }), bytes);
    std::vector<double> cold;
    for (int i = 0; i < args.repeat; ++i) cold.push_back(cold_read(file));
    if (*std::min_element(cold.begin(), cold.end()) > 0) report(format, "cold", cold, bytes);
  }
  ScalarField phi = mesh.phi_field();
  for (const char* ext : {".sol", ".solb"}) {
    const fs::path file = scratch / (std::string("phi") + ext);
    auto runs = repeat([&] { write_scalar_sol(file, phi); });
    const auto bytes = fs::file_size(file);
    report(ext + 1, "write", runs, bytes);
    flush_to_disk(file);
    report(ext + 1, "read", repeat([&] { (void)read_scalar_sol(file, phi.size()); }), bytes);
  }
  fs::remove_all(scratch);
  fmt::print("CSV: {}\n", args.csv);
  return 0;
}
