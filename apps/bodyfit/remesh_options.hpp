#pragma once
// The sizing options shared by `bodyfit remesh` and `bodyfit discretize` (same names as mmgs).
#include <bodyfit/remesh.hpp>

#include <CLI/CLI.hpp>

namespace bodyfit::cli {

/// Adds --hmin --hmax --hausd --hgrad --angle, writing into `options` (which must outlive parsing).
void add_remesh_options(CLI::App& command, RemeshOptions& options);

}  // namespace bodyfit::cli
