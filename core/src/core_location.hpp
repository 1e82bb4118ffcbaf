#pragma once
// Where the running libbodyfit_core lives: the plugins and the GDAL module are found beside it
// (<libdir>/bodyfit/...), in the build tree and in any install prefix alike, with no path compiled in.
#include <filesystem>

namespace bodyfit {

/// The directory of the libbodyfit_core actually loaded (empty if it cannot be told).
std::filesystem::path core_library_directory();

}  // namespace bodyfit
