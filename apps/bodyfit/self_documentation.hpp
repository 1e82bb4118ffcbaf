#pragma once
// The driver describing itself from its own command-line definition, so neither can drift from
// --help: a man page (roff: each command's --help text as it prints) and a bash completion script
// (the commands, then each command's options and file names). The build writes both and the
// install puts them where man and bash-completion look (cmake/BodyfitInstall.cmake).
//   bodyfit --man-page > bodyfit.1
//   bodyfit --bash-completion > bodyfit
#include <CLI/CLI.hpp>

#include <string>

namespace bodyfit::cli {

std::string man_page(CLI::App& app, const std::string& version);
std::string bash_completion(CLI::App& app);

}  // namespace bodyfit::cli
