#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/app/run_directory.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <regex>
#include <string_view>
#include <system_error>

namespace bodyfit {
namespace {

namespace fs = std::filesystem;

/// The state number of a per-state file (step_<n>.vtu, snap_<n>.png), or −1.
long state_of(const std::string& name) {
  static const std::regex per_state(R"((?:step_([0-9]+)\.vtu)|(?:snap_([0-9]+)\.png))");
  std::smatch m;
  if (!std::regex_match(name, m, per_state)) return -1;
  const std::string digits = m[1].matched ? m[1].str() : m[2].str();
  return digits.size() > 9 ? -1 : std::stol(digits);
}

template <class Keep>
std::size_t remove_files(const fs::path& dir, Keep matches) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  std::size_t removed = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file(ec) || !matches(entry.path().filename().string())) continue;
    fs::remove(entry.path(), ec);
    if (ec)
      throw IoError(fmt::format("{}: cannot remove ({})", entry.path().string(), ec.message()));
    ++removed;
  }
  return removed;
}

}  // namespace

bool is_run_output(const std::string& file_name) {
  static constexpr std::array<std::string_view, 6> fixed = {"case.toml",  "checkpoint.bin", "history.csv",
                                                            "series.pvd", "final.mesh",     "final.sol"};
  return std::find(fixed.begin(), fixed.end(), file_name) != fixed.end() || state_of(file_name) >= 0 ||
         is_atomic_temporary(file_name);
}

std::vector<fs::path> run_outputs(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file(ec) && is_run_output(entry.path().filename().string())) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

void remove_run_outputs(const fs::path& dir, const std::vector<std::string>& model_files) {
  remove_files(dir, [&](const std::string& name) {
    return is_run_output(name) || std::find(model_files.begin(), model_files.end(), name) != model_files.end();
  });
}

std::size_t remove_stale_temporaries(const fs::path& dir) { return remove_files(dir, is_atomic_temporary); }

std::size_t remove_states_from(const fs::path& dir, int first) {
  return remove_files(dir, [first](const std::string& name) { return state_of(name) >= first; });
}

}  // namespace bodyfit
