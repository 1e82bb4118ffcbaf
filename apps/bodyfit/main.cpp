// bodyfit: body-fitted tracking of a region moving inside a fixed surface.
#include "commands.hpp"
#include "validators.hpp"
#include "mmg_spellings.hpp"
#include "self_documentation.hpp"

#include <bodyfit/app/huge_page_heap.hpp>
#include <bodyfit/app/shared_data.hpp>
#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/guards.hpp>

#include <fmt/format.h>

#include <csignal>
#include <new>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <string_view>
#include <exception>
#include <optional>
#include <vector>

namespace bodyfit::cli {
namespace {

std::vector<std::pair<int, CommandSetup>>& registry() {
  static std::vector<std::pair<int, CommandSetup>> commands;
  return commands;
}

}  // namespace

CommandRegistration::CommandRegistration(int order, CommandSetup setup) {
  registry().emplace_back(order, std::move(setup));
}

}  // namespace bodyfit::cli

int main(int argc, char** argv) {
  using namespace bodyfit;
  keep_freed_blocks();
  // A file-size limit (ulimit -f) makes a write fail with EFBIG, an I/O error that removes its
  // temporary, instead of SIGXFSZ killing the process with the temporary left behind.
  std::signal(SIGXFSZ, SIG_IGN);
  // The build's own documentation of the command line (self_documentation.hpp) names no path of
  // this machine.
  const bool documenting = argc == 2 && (std::string_view(argv[1]) == "--man-page" ||
                                         std::string_view(argv[1]) == "--bash-completion");
  const std::filesystem::path data = documenting ? std::filesystem::path() : shared_data_directory();
  const std::string examples =
      data.empty() ? std::string("the example cases in share/bodyfit/cases of the install prefix (meshes/cases "
                                 "of the sources)")
                   : fmt::format("the example cases in {}, e.g.\n  bodyfit run {} -o out", (data / "cases").string(),
                                 (data / "cases" / "sphere_cap.toml").string());
  CLI::App app{
      "bodyfit — track a region G(t) moving inside a fixed triangulated surface S, keeping G and\n"
      "S\\G exactly meshed at every step (level set + body-fitted remeshing).\n\n"
      "Every stage is also a subcommand that reads and writes Medit .mesh/.sol files, so it can\n"
      "replace mmgs, mshdist or advect one stage at a time. Start with `bodyfit run case.toml`:\n" +
          examples + "\nor with `bodyfit mesh sphere --faces 20000 -o s.mesh`. Each command's --help explains it.",
      "bodyfit"};
  app.set_version_flag("--version", std::string("bodyfit ") + config::version);
  app.require_subcommand(1);
  int verbosity = 0;
  app.add_flag("-v,--verbose", verbosity, "more log output (-vv for debug traces)");
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "only errors");
  int threads = 0;
  app.add_option("--threads", threads, "worker threads of the parallel stages (0: all cores); results do not depend on it")
      ->check(CLI::Range(0, 4096));
  std::size_t max_faces = default_max_faces();
  auto* max_faces_option =
      app.add_option("--max-faces", max_faces,
                     fmt::format("refuse to build or remesh to more faces than this, estimated before starting (0: no "
                                 "limit; default: what fits in 3/4 of this machine's memory at {:.0f} bytes per face)",
                                 kBytesPerFace))
          ->check(bodyfit::cli::count());
  if (!documenting) max_faces_option->capture_default_str();

  auto& commands = cli::registry();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<cli::Command> added;
  for (auto& [order, setup] : commands) added.push_back(setup(app));
  if (documenting)
    return std::fputs((std::string_view(argv[1]) == "--man-page" ? cli::man_page(app, config::version)
                                                                   : cli::bash_completion(app))
                          .c_str(),
                      stdout) < 0;

  // MMG's spellings (-hmax 0.1, -in, -out, -sol, -ls, -nr): translated on discretize and remesh,
  // refused elsewhere (mmg_spellings.hpp) — never the help and exit 0.
  std::vector<std::string> names;
  for (const auto& command : added) names.push_back(command.app->get_name());
  auto translation = cli::translate_mmg_spellings(std::vector<std::string>(argv + 1, argv + argc), names);
  if (translation.error) {
    std::fprintf(stderr, "bodyfit: %s\n", translation.error->c_str());
    return int(ExitCode::Usage);
  }
  std::vector<std::string> arguments = std::move(translation.arguments);
  std::reverse(arguments.begin(), arguments.end());  // CLI11 takes the arguments in reverse

  try {
    app.parse(arguments);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help, version or the error
    return code == 0 ? 0 : int(ExitCode::Usage);  // not CLI11's raw 105-114
  }

  for (const auto& command : added)
    if (command.app->parsed() && command.on_huge_pages) restart_on_huge_pages(argv);

  set_max_faces(max_faces);
  // oneTBB's limit for the whole process, the plugins' parallel loops included.
  std::optional<tbb::global_control> thread_limit;
  if (threads > 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(threads));

  auto logger = spdlog::stderr_color_mt("bodyfit");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%T.%e] %^%l%$ %v");
  spdlog::set_level(quiet ? spdlog::level::err
                          : verbosity >= 2 ? spdlog::level::trace
                          : verbosity == 1 ? spdlog::level::debug
                                           : spdlog::level::info);

  try {
    for (auto& command : added) {
      if (!command.app->parsed()) continue;
      if (command.on_huge_pages && heap_on_huge_pages())
        spdlog::debug("heap on transparent huge pages (GLIBC_TUNABLES glibc.malloc.hugetlb=1)");
      return command.run();
    }
    spdlog::error("no subcommand given (see --help)");
    return int(ExitCode::Usage);
  } catch (const std::exception& e) {
    const ExitCode code = exit_code_of(e);
    if (code == ExitCode::Internal) spdlog::error("internal error: {}", e.what());
    else if (dynamic_cast<const std::bad_alloc*>(&e))
      spdlog::error("out of memory: the input or the options ask for more than this machine has ({}; the estimates "
                    "refuse what they foresee: see --max-faces)",
                    e.what());
    else spdlog::error("{}", e.what());
    return int(code);
  }
}
