#pragma once
// Where bodyfit's shared data is: the example cases (cases/), their DEMs and parts (dem/, parts/)
// and the example plugins (examples/) — <prefix>/share/bodyfit once installed, the sources' from a
// build tree.
#include <filesystem>

namespace bodyfit {

/// The shared data directory beside the running library (empty when it cannot be found).
std::filesystem::path shared_data_directory();

}  // namespace bodyfit
