// The readers behind the fuzz targets (fuzz_inputs.hpp).
#include "fuzz_inputs.hpp"

// The Medit parser's in-memory entry point is private to the core's I/O sources.
#include "../../core/src/io_internal.hpp"

#include <bodyfit/app/case_config.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/terrain.hpp>
#include <bodyfit/io.hpp>

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <unistd.h>

namespace bodyfit::fuzz {
namespace {

namespace fs = std::filesystem;

/// A private directory for the files of path-only readers, removed at exit.
class Scratch {
 public:
  Scratch() {
    const fs::path base = fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    dir_ = base / ("bodyfit_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

  /// `bytes` written to <dir>/<name>.
  fs::path write(const std::string& name, std::string_view bytes) const {
    fs::path file = dir_ / name;
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out.flush()) throw std::runtime_error("fuzz: cannot write " + file.string());
    return file;
  }

 private:
  fs::path dir_;
};

const Scratch& scratch() {
  static const Scratch instance;
  return instance;
}

/// Whether the bytes start with a binary Medit file's endianness code (1 in either byte order).
bool medit_binary(std::string_view bytes) {
  using namespace std::string_view_literals;
  return bytes.starts_with("\x01\x00\x00\x00"sv) || bytes.starts_with("\x00\x00\x00\x01"sv);
}

}  // namespace

Reader reader_named(std::string_view target) {
  static constexpr std::array<std::pair<std::string_view, Reader>, 7> names{{
      {"mesh_text", Reader::MeshText},
      {"mesh_binary", Reader::MeshBinary},
      {"sol", Reader::Sol},
      {"openmesh", Reader::OpenMesh},
      {"esri_grid", Reader::EsriGrid},
      {"case", Reader::Case},
      {"checkpoint", Reader::Checkpoint},
  }};
  for (const auto& [name, reader] : names)
    if (name == target) return reader;
  throw std::invalid_argument("no fuzz target named '" + std::string(target) + "'");
}

void read_input(Reader reader, std::string_view bytes) {
  switch (reader) {
    case Reader::MeshText:
    case Reader::MeshBinary: {
      const fs::path name = reader == Reader::MeshText ? "fuzz.mesh" : "fuzz.meshb";
      io_detail::build_mesh(io_detail::parse_medit(bytes, name), name, ReadOptions{});
      return;
    }
    case Reader::Sol:
      read_sol_all(scratch().write(medit_binary(bytes) ? "fuzz.solb" : "fuzz.sol", bytes));
      return;
    case Reader::OpenMesh: {
      if (bytes.empty()) return;
      // The first byte picks the format (0 OBJ, 1 OFF, 2 STL, 3 PLY, modulo 4: the regression
      // inputs' first bytes were chosen in this order).
      static constexpr std::array<const char*, 4> names{"fuzz.obj", "fuzz.off", "fuzz.stl", "fuzz.ply"};
      read_mesh(scratch().write(names[static_cast<unsigned char>(bytes[0]) % names.size()], bytes.substr(1)));
      return;
    }
    case Reader::EsriGrid:
      read_esri_ascii(scratch().write("fuzz.asc", bytes));
      return;
    case Reader::Case:
      read_case(scratch().write("case.toml", bytes));
      return;
    case Reader::Checkpoint: {
      std::istringstream in{std::string(bytes)};
      read_checkpoint(in, "fuzz checkpoint");
      return;
    }
  }
}

}  // namespace bodyfit::fuzz
