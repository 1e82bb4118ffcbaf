#pragma once
// Reading a TOML table of parameters (a model's [model] table, a case section) with validation.
//
//   bodyfit::Parameters p(table, "model");
//   speed_ = p.number("speed", 1.0, {.min = 0});       // default 1, must be >= 0
//   mode_ = p.choice("mode", "fast", {"fast", "exact"});
//   p.reject_unknown();  // "unknown key 'sped' in [model]; did you mean 'speed'?"
//
// Every getter records its key as known; reject_unknown() then refuses any other key of the table,
// suggesting the closest known key. Errors are InputError naming where the value was written
// ("case.toml:12: ", from toml++'s source region, when known), the section, the key and the
// expected value: "case.toml:12: [model] speed: -1 is out of range [0, inf)".
#include <bodyfit/velocity_model.hpp>

#include <toml++/toml.h>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bodyfit {

/// Closed interval of accepted values (open ends with the flags).
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;  ///< true: value > min
  bool max_exclusive = false;  ///< true: value < max
  bool contains(double value) const;
  std::string describe() const;  ///< "[0, inf)", "(0, 1]"
};

/// Where a TOML value was written, as a message prefix: "case.toml:12: ", "line 12: " for a table
/// parsed from a string, "" when unknown (a value set by --set, a table built in code).
std::string location_of(const toml::node& node);

class Parameters {
 public:
  /// `section` names the table in messages ("model" gives "[model]").
  explicit Parameters(const toml::table& table, std::string section = "model");
  /// An optional table: absent (nullptr) reads as an empty table, so every getter gives its fallback.
  Parameters(const toml::table* table, std::string section);

  bool has(std::string_view key) const;
  /// A number (TOML integer or float), `fallback` when absent.
  double number(std::string_view key, double fallback, Range range = {});
  /// A required number: absent is an error.
  double required_number(std::string_view key, Range range = {});
  std::int64_t integer(std::string_view key, std::int64_t fallback,
                       std::int64_t min = std::numeric_limits<std::int64_t>::min(),
                       std::int64_t max = std::numeric_limits<std::int64_t>::max());
  bool boolean(std::string_view key, bool fallback);
  std::string string(std::string_view key, std::string fallback);
  /// A file name, resolved against the directory of the file the value was parsed from (a case
  /// file read with toml::parse_file: `field = "data/field.sol"` next to the case works from any
  /// working directory). Absolute names are kept; a value with no source file (from `--set`, or
  /// a table parsed from a string) resolves against the current working directory. The result is
  /// absolute and lexically normal; `fallback` is returned as given when the key is absent.
  std::filesystem::path path(std::string_view key, std::string fallback = "");
  /// A string among `allowed`.
  std::string choice(std::string_view key, std::string fallback, const std::vector<std::string>& allowed);
  /// An array of numbers; `size` (when given) is the required length.
  std::vector<double> numbers(std::string_view key, std::vector<double> fallback,
                              std::optional<std::size_t> size = std::nullopt, Range range = {});
  /// An array of arrays of `size` numbers each (points, axes: `[[x, y], ...]`); empty when absent.
  std::vector<std::vector<double>> number_arrays(std::string_view key, std::size_t size, Range range = {});
  /// The sub-table `key` (empty when absent).
  const toml::table* table(std::string_view key);

  /// Mark keys as known without reading them (e.g. "name", handled by the driver).
  void accept(std::string_view key);
  void accept(const std::vector<ParameterInfo>& infos);
  /// Throw InputError for the first key of the table that no getter asked for.
  void reject_unknown() const;
  /// Refuse keys that do not apply to the variant another key chose: "[surface] extent: does not
  /// apply to generator 'sphere'" for forbid({"extent", ...}, "to generator 'sphere'").
  void forbid(const std::vector<std::string>& keys, std::string_view reason) const;

  /// Errors for checks no getter expresses (several keys together, a value set): located at the
  /// key's value when present, else at the table; "[section] key: what" / "[section] what".
  [[noreturn]] void fail(std::string_view key, const std::string& what) const;
  [[noreturn]] void fail(const std::string& what) const;

  const std::string& section() const { return section_; }

 private:
  const toml::node* find(std::string_view key);

  const toml::table& table_;
  std::string section_;
  std::vector<std::string> known_;
};

/// Levenshtein distance (insertions, deletions, substitutions), for "did you mean" suggestions.
std::size_t edit_distance(std::string_view a, std::string_view b);
/// The candidate closest to `word` when it is close enough to be a plausible typo, else "".
std::string closest_match(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace bodyfit
