#pragma once
// Subcommand registry of the `bodyfit` driver. Each cmd_<name>.cpp defines one subcommand and
// registers it with a static BODYFIT_COMMAND(...) line, so adding a command is adding a file.
#include <CLI/CLI.hpp>

#include <functional>
#include <string>

namespace bodyfit::cli {

/// A subcommand added to the application, and what runs it (returns the process exit code).
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
  /// A one-shot stage whose time goes mostly into first touching its arrays: run on huge pages
  /// (bodyfit/app/huge_page_heap.hpp).
  bool on_huge_pages = false;
};
/// Adds the subcommand to `app` and returns it with its runner.
using CommandSetup = std::function<Command(CLI::App& app)>;

struct CommandRegistration {
  CommandRegistration(int order, CommandSetup setup);
};

}  // namespace bodyfit::cli

#define BODYFIT_CONCAT_INNER(a, b) a##b
#define BODYFIT_CONCAT(a, b) BODYFIT_CONCAT_INNER(a, b)
/// Register a subcommand; `order` fixes its place in --help.
#define BODYFIT_COMMAND(order, setup) \
  static ::bodyfit::cli::CommandRegistration BODYFIT_CONCAT(bodyfit_command_, __LINE__)(order, setup)
