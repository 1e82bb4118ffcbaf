#pragma once
// MMG's option spellings (mmgs -in a.mesh -sol phi.sol -ls -hmax 0.1 -out b.mesh) on the command
// line of `bodyfit`. CLI11 would read "-hmax" as the flags -h -m -a -x, print the help and exit 0, and
// a script written for mmgs would carry on as if the stage had run. So before parsing, on
// `discretize` and `remesh` the spellings with a bodyfit equivalent become it (then both are
// drop-ins for `mmgs` and `mmgs -ls`), and every other MMG spelling, or one on another subcommand,
// is refused with a message naming the bodyfit option.
#include <optional>
#include <string>
#include <vector>

namespace bodyfit::cli {

struct Translation {
  std::vector<std::string> arguments;  ///< the command line with MMG's spellings replaced
  std::optional<std::string> error;    ///< set when a spelling is refused (a usage error)
};

/// `arguments` without the program name; `subcommands` the names of bodyfit's subcommands.
Translation translate_mmg_spellings(std::vector<std::string> arguments, const std::vector<std::string>& subcommands);

}  // namespace bodyfit::cli
