#pragma once
// The readers the fuzz targets of tests/fuzz feed, one per target, shared with the regression test
// (tests/test_fuzz_regressions.cpp) that replays the inputs the fuzzers found.
#include <string_view>

namespace bodyfit::fuzz {

enum class Reader {
  MeshText,    ///< Medit .mesh (in memory: parse_medit + build_mesh)
  MeshBinary,  ///< Medit .meshb (in memory)
  Sol,         ///< read_sol_all on a .solb when the bytes start with a binary Medit code, else a .sol
  OpenMesh,    ///< read_mesh on .obj, .off, .stl or .ply: the first byte chooses (byte % 4), the rest is the file
  EsriGrid,    ///< read_esri_ascii
  Case,        ///< read_case: the TOML case loader
  Checkpoint,  ///< read_checkpoint (in memory)
};

/// The reader of a fuzz target ("mesh_text", "mesh_binary", "sol", "openmesh", "esri_grid", "case",
/// "checkpoint"); std::invalid_argument for another name.
Reader reader_named(std::string_view target);

/// Read `bytes` as `reader` reads a file. Input it refuses must end in InputError: any other
/// exception, a crash, a sanitizer report or a hang is a bug. Readers that take only a path get
/// the bytes through a file in a temporary directory (/dev/shm when there is one).
void read_input(Reader reader, std::string_view bytes);

}  // namespace bodyfit::fuzz
