#pragma once
// Parameters: declared once, read through the declaration, and every key that is set either read
// or refused.
//
// A velocity model declares what it takes (VelocityModel::parameters), one ParameterDecl per key:
//
//   return {ParameterDecl::number("speed", "m/s", "normal speed of the front").fallback(1.0).at_least(0),
//           ParameterDecl::choice("mode", {"fast", "exact"}, "how the speed is evaluated").fallback("fast"),
//           ParameterDecl::number("flow.speed", "m/s", "speed of [model.flow]").fallback(0)};
//
// and reads its values through them in configure(Parameters& p):
//
//   speed_ = p.number("speed");                 // the declared default and range
//   mode_ = p.choice("mode");
//   Parameters& flow = p.section("flow");       // [model.flow]: keys declared as "flow.<key>"
//
// A key read that was not declared is a programming error (std::logic_error: the declaration and
// configure() have one source of truth). After configure() the driver calls check_consumed(): a key
// of the table that is not declared is an InputError with a suggestion ("unknown key 'sped' in
// [model]; did you mean 'speed'?"), and a declared key that configure() did not read is refused too
// — a value that takes no effect is never silently dropped. A model says why with not_used():
//
//   if (table_given) p.not_used("speed", "it is set per class by [model.classes]; give it in the table");
//
// Errors are InputError naming where the value was written ("case.toml:12: ", from toml++'s source
// region, when known), the section, the key and what was expected:
// "case.toml:12: [model] speed: -1 is out of range [0, inf)".
//
// The driver's own sections of a case (no declarations) use the same reader with the default and
// range given at each call: p.number("dt", 0.1, {.min = 0}), then p.reject_unknown().
#include <toml++/toml.h>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
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
  bool unbounded() const;
  std::string describe() const;  ///< "[0, inf)", "(0, 1]"
};

enum class ParameterType {
  Number,   ///< a TOML integer or float
  Integer,  ///< a TOML integer
  Boolean,
  String,
  Choice,   ///< a string among ParameterDecl::choices
  Path,     ///< a file name, resolved against the case file's directory
  Numbers,  ///< an array of numbers (ParameterDecl::size of them, when > 0)
  Points,   ///< an array of arrays of ParameterDecl::size numbers ([[x, y], ...])
  Strings,  ///< an array of strings
  Table,    ///< a table the model reads as it is (its keys are data, not parameters)
};
std::string_view to_string(ParameterType type);

/// One parameter: its key, type, unit, default, accepted values and meaning. Made with the
/// factories and refined with the modifiers, each returning the changed declaration:
///   ParameterDecl::number("speed", "m/s", "normal speed of the front").fallback(0.4).positive()
struct ParameterDecl {
  std::string key;          ///< "speed"; a key of a sub-table is dotted: "flow.speed" ([model.flow] speed)
  ParameterType type = ParameterType::Number;
  std::string unit;         ///< "m/s", "1" (dimensionless), "" (no unit: strings, files, switches)
  std::string description;  ///< one sentence: what it does
  /// The default as it reads in TOML ("1.5", "\"fast\"", "[0, 0]"), a phrase in parentheses for
  /// one computed by configure ("(12·R0)", "(the mean edge length)"), or "" when there is none
  /// (required, or absent means "off").
  std::string default_text;
  Range range;                       ///< Number, Integer, Numbers, Points: every value in it
  std::vector<std::string> choices;  ///< Choice
  std::size_t size = 0;              ///< Numbers: the length (0: any); Points: numbers per point
  bool required = false;

  static ParameterDecl number(std::string key, std::string unit, std::string description);
  static ParameterDecl integer(std::string key, std::string unit, std::string description);
  static ParameterDecl boolean(std::string key, std::string description);
  static ParameterDecl string(std::string key, std::string description);
  static ParameterDecl choice(std::string key, std::vector<std::string> choices, std::string description);
  static ParameterDecl path(std::string key, std::string description);
  static ParameterDecl numbers(std::string key, std::size_t size, std::string unit, std::string description);
  static ParameterDecl points(std::string key, std::size_t size, std::string unit, std::string description);
  static ParameterDecl strings(std::string key, std::string description);
  static ParameterDecl table(std::string key, std::string description);

  ParameterDecl fallback(double value) const;
  ParameterDecl fallback(std::int64_t value) const;
  ParameterDecl fallback(int value) const { return fallback(std::int64_t(value)); }
  ParameterDecl fallback(bool value) const;
  ParameterDecl fallback(const char* value) const;  ///< String, Choice, Path
  ParameterDecl fallback(std::vector<double> values) const;
  /// A default configure() computes (then it reads the key with an explicit fallback).
  ParameterDecl computed(std::string phrase) const;
  ParameterDecl within(Range accepted) const;
  ParameterDecl positive() const;            ///< > 0
  ParameterDecl at_least(double min) const;  ///< ≥ min
  ParameterDecl require() const;             ///< absent is an error

  // The typed default (set by fallback()).
  std::optional<double> number_default;
  std::optional<std::int64_t> integer_default;
  std::optional<bool> boolean_default;
  std::optional<std::string> string_default;
  std::optional<std::vector<double>> numbers_default;
};

/// Where a TOML value was written, as a message prefix: "case.toml:12: ", "line 12: " for a table
/// parsed from a string, "" when unknown (a value set by --set, a table built in code).
std::string location_of(const toml::node& node);

class Parameters {
 public:
  /// A table read with declarations (a model's). `section` names the table in messages ("model"
  /// gives "[model]").
  Parameters(const toml::table& table, std::vector<ParameterDecl> declarations, std::string section = "model");
  /// A table read without declarations (the driver's own sections): each getter gives its default.
  explicit Parameters(const toml::table& table, std::string section = "model");
  /// An optional table: absent (nullptr) reads as an empty table, so every getter gives its fallback.
  Parameters(const toml::table* table, std::string section);
  ~Parameters();
  Parameters(const Parameters&) = delete;
  Parameters& operator=(const Parameters&) = delete;

  bool has(std::string_view key) const;
  /// Whether `key` is set to a table (a parameter that is a number or a table of details).
  bool is_table(std::string_view key) const;
  /// The declaration of `key` of this table (nullptr without declarations, or when undeclared).
  const ParameterDecl* declaration(std::string_view key) const;
  /// Declare more keys while configuring: a model whose parameters depend on one of its keys (the
  /// python model learns its class's parameters from `module` and `class`). Call it before
  /// section(); the keys are then read and checked as the others.
  void declare(std::vector<ParameterDecl> more);

  // With declarations: the declared default (required when there is none) and range. Without,
  // string() and path() give "" when the key is absent; the others need a fallback.
  double number(std::string_view key);
  std::int64_t integer(std::string_view key);
  bool boolean(std::string_view key);
  std::string string(std::string_view key);
  std::string choice(std::string_view key);
  std::filesystem::path path(std::string_view key);
  std::vector<double> numbers(std::string_view key);
  std::vector<std::vector<double>> points(std::string_view key);
  /// An array of strings (absent: empty).
  std::vector<std::string> strings(std::string_view key);

  // An explicit fallback (without declarations; with them, for a default configure() computes —
  // the declared range and choices still apply).
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
  std::filesystem::path path(std::string_view key, std::string fallback);
  /// The same, with a value that has no source file resolved against `sourceless` instead of the
  /// working directory (a case given as text with the directory it stands for).
  std::filesystem::path path(std::string_view key, std::string fallback, const std::filesystem::path& sourceless);
  /// A string among `allowed`.
  std::string choice(std::string_view key, std::string fallback, const std::vector<std::string>& allowed);
  /// An array of numbers; `size` (when given) is the required length.
  std::vector<double> numbers(std::string_view key, std::vector<double> fallback,
                              std::optional<std::size_t> size = std::nullopt, Range range = {});
  /// An array of arrays of `size` numbers each (points, axes: `[[x, y], ...]`); empty when absent.
  std::vector<std::vector<double>> number_arrays(std::string_view key, std::size_t size, Range range = {});
  /// The sub-table `key` as it is, read whole (its keys are data: ParameterType::Table); null when absent.
  const toml::table* table(std::string_view key);
  /// The sub-table [section.key] as parameters (declared as "key.<name>"); absent reads as empty.
  Parameters& section(std::string_view key);

  /// Mark keys as read without reading them (the driver's own sections: e.g. "name").
  void accept(std::string_view key);
  /// Why a declared key is not used with the values read so far: the message check_consumed()
  /// gives when it is set ("it is set per class by [model.classes]").
  void not_used(std::string_view key, std::string reason);
  /// Throw InputError for the first key of the table no getter asked for (this table only).
  void reject_unknown() const;
  /// Throw InputError for the first key set here or in a section that was not read: an unknown
  /// key with a suggestion, or a declared one the settings do not use, with not_used()'s reason.
  void check_consumed() const;
  /// Every key read so far, dotted from this table ("flow.speed"), sections included.
  std::vector<std::string> consumed() const;
  /// Refuse keys that do not apply to the variant another key chose: "[surface] extent: does not
  /// apply to generator 'sphere'" for forbid({"extent", ...}, "to generator 'sphere'").
  void forbid(const std::vector<std::string>& keys, std::string_view reason) const;

  /// Errors for checks no getter expresses (several keys together, a value set): located at the
  /// key's value when present, else at the table; "[section] key: what" / "[section] what".
  [[noreturn]] void fail(std::string_view key, const std::string& what) const;
  [[noreturn]] void fail(const std::string& what) const;

  const std::string& section() const { return section_; }
  const std::vector<ParameterDecl>& declarations() const;

 private:
  Parameters(const toml::table& table, std::shared_ptr<const std::vector<ParameterDecl>> declarations,
             std::string section, std::string prefix);
  const toml::node* find(std::string_view key);
  /// The declaration of `key` in declared mode (nullptr without declarations); logic_error when
  /// the model reads a key it did not declare, or as another type.
  const ParameterDecl* declared(std::string_view key, std::initializer_list<ParameterType> types) const;
  std::vector<std::string> known_keys() const;

  const toml::table& table_;
  std::shared_ptr<const std::vector<ParameterDecl>> declarations_;  ///< null: no declarations
  std::string section_;
  std::string prefix_;  ///< of this table's keys in the declarations ("flow.")
  std::vector<std::string> known_;
  std::map<std::string, std::string, std::less<>> not_used_;
  std::map<std::string, std::unique_ptr<Parameters>, std::less<>> sections_;
};

/// Levenshtein distance (insertions, deletions, substitutions), for "did you mean" suggestions.
std::size_t edit_distance(std::string_view a, std::string_view b);
/// The candidate closest to `word` when it is close enough to be a plausible typo, else "".
std::string closest_match(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace bodyfit
