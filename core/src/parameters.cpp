#include <bodyfit/parameters.hpp>

#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

namespace bodyfit {

namespace {

std::string format_bound(double value) {
  if (std::isinf(value)) return value < 0 ? "-inf" : "inf";
  return fmt::format("{}", value);
}

const char* type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

std::optional<double> as_number(const toml::node& node) {
  if (auto i = node.as_integer()) return static_cast<double>(i->get());
  if (auto d = node.as_floating_point()) return d->get();
  return std::nullopt;
}

/// Why `value` is refused by `range` ("" when accepted): TOML's inf and nan are never accepted,
/// whatever the range (no parameter means "infinitely"; an absent key gives the default).
std::string refusal(double value, const Range& range) {
  if (!std::isfinite(value)) return fmt::format("{} is not a finite number", value);
  if (!range.contains(value)) return fmt::format("{} is out of range {}", value, range.describe());
  return {};
}

/// "[a, b]" for integers, the type's limits shown as infinite ("[0, inf)").
std::string describe_integers(std::int64_t min, std::int64_t max) {
  using limits = std::numeric_limits<std::int64_t>;
  return fmt::format("{}, {}", min == limits::min() ? "(-inf" : fmt::format("[{}", min),
                     max == limits::max() ? "inf)" : fmt::format("{}]", max));
}

/// What an absent table reads as.
const toml::table& empty_table() {
  static const toml::table empty;
  return empty;
}

}  // namespace

std::string location_of(const toml::node& node) {
  const auto& source = node.source();
  if (source.begin.line == 0) return source.path ? *source.path + ": " : "";
  if (source.path) return fmt::format("{}:{}: ", *source.path, source.begin.line);
  return fmt::format("line {}: ", source.begin.line);
}

bool Range::contains(double value) const {
  if (std::isnan(value)) return false;
  bool above = min_exclusive ? value > min : value >= min;
  bool below = max_exclusive ? value < max : value <= max;
  return above && below;
}

std::string Range::describe() const {
  return fmt::format("{}{}, {}{}", min_exclusive || std::isinf(min) ? '(' : '[', format_bound(min),
                     format_bound(max), max_exclusive || std::isinf(max) ? ')' : ']');
}

Parameters::Parameters(const toml::table& table, std::string section) : table_(table), section_(std::move(section)) {}

Parameters::Parameters(const toml::table* table, std::string section)
    : Parameters(table ? *table : empty_table(), std::move(section)) {}

bool Parameters::has(std::string_view key) const { return table_.contains(key); }

const toml::node* Parameters::find(std::string_view key) {
  accept(key);
  return table_.get(key);
}

void Parameters::fail(std::string_view key, const std::string& what) const {
  const toml::node* node = table_.get(key);
  throw InputError(fmt::format("{}[{}] {}: {}", location_of(node ? *node : table_), section_, key, what));
}

void Parameters::fail(const std::string& what) const {
  throw InputError(fmt::format("{}[{}] {}", location_of(table_), section_, what));
}

double Parameters::number(std::string_view key, double fallback, Range range) {
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = as_number(*node);
  if (!value) fail(key, fmt::format("expected a number, got {}", type_name(*node)));
  if (auto why = refusal(*value, range); !why.empty()) fail(key, why);
  return *value;
}

double Parameters::required_number(std::string_view key, Range range) {
  if (!has(key)) fail(key, "required (a number in " + range.describe() + ")");
  return number(key, 0.0, range);
}

std::int64_t Parameters::integer(std::string_view key, std::int64_t fallback, std::int64_t min, std::int64_t max) {
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = node->as_integer();
  if (!value) fail(key, fmt::format("expected an integer, got {}", type_name(*node)));
  std::int64_t v = value->get();
  if (v < min || v > max) fail(key, fmt::format("{} is out of range {}", v, describe_integers(min, max)));
  return v;
}

bool Parameters::boolean(std::string_view key, bool fallback) {
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = node->as_boolean();
  if (!value) fail(key, fmt::format("expected true or false, got {}", type_name(*node)));
  return value->get();
}

std::string Parameters::string(std::string_view key, std::string fallback) {
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = node->as_string();
  if (!value) fail(key, fmt::format("expected a string, got {}", type_name(*node)));
  return value->get();
}

std::filesystem::path Parameters::path(std::string_view key, std::string fallback) {
  const bool present = has(key);
  std::string text = string(key, std::move(fallback));
  if (!present || text.empty()) return text;
  std::filesystem::path name(text);
  if (name.is_absolute()) return name.lexically_normal();
  const auto& source = table_.get(key)->source();
  // toml++ keeps the name given to parse_file, relative to the working directory of that call.
  std::filesystem::path base = source.path ? std::filesystem::path(*source.path).parent_path() : std::filesystem::path();
  return std::filesystem::absolute(base / name).lexically_normal();
}

std::string Parameters::choice(std::string_view key, std::string fallback, const std::vector<std::string>& allowed) {
  std::string value = string(key, std::move(fallback));
  if (std::find(allowed.begin(), allowed.end(), value) == allowed.end()) {
    std::string hint;
    if (auto near = closest_match(value, allowed); !near.empty()) hint = fmt::format("; did you mean '{}'?", near);
    fail(key, fmt::format("'{}' is not one of {}{}", value, fmt::join(allowed, ", "), hint));
  }
  return value;
}

std::vector<double> Parameters::numbers(std::string_view key, std::vector<double> fallback,
                                        std::optional<std::size_t> size, Range range) {
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto array = node->as_array();
  if (!array) fail(key, fmt::format("expected an array of numbers, got {}", type_name(*node)));
  std::vector<double> values;
  for (const auto& element : *array) {
    auto value = as_number(element);
    if (!value) fail(key, fmt::format("expected an array of numbers, found {} in it", type_name(element)));
    if (auto why = refusal(*value, range); !why.empty()) fail(key, why);
    values.push_back(*value);
  }
  if (size && values.size() != *size) fail(key, fmt::format("expected {} numbers, got {}", *size, values.size()));
  return values;
}

std::vector<std::vector<double>> Parameters::number_arrays(std::string_view key, std::size_t size, Range range) {
  const toml::node* node = find(key);
  if (!node) return {};
  auto array = node->as_array();
  if (!array) fail(key, fmt::format("expected an array of arrays of {} numbers, got {}", size, type_name(*node)));
  std::vector<std::vector<double>> rows;
  for (const auto& element : *array) {
    const std::size_t item = rows.size() + 1;  // counted from 1, as a reader counts
    auto row = element.as_array();
    if (!row) fail(key, fmt::format("item {}: expected an array of {} numbers, got {}", item, size, type_name(element)));
    if (row->size() != size) fail(key, fmt::format("item {}: expected {} numbers, got {}", item, size, row->size()));
    std::vector<double> values;
    for (const auto& entry : *row) {
      auto value = as_number(entry);
      if (!value) fail(key, fmt::format("item {}: expected {} numbers, found {} in it", item, size, type_name(entry)));
      if (auto why = refusal(*value, range); !why.empty()) fail(key, fmt::format("item {}: {}", item, why));
      values.push_back(*value);
    }
    rows.push_back(std::move(values));
  }
  return rows;
}

const toml::table* Parameters::table(std::string_view key) {
  const toml::node* node = find(key);
  if (!node) return nullptr;
  auto t = node->as_table();
  if (!t) fail(key, fmt::format("expected a table, got {}", type_name(*node)));
  return t;
}

void Parameters::accept(std::string_view key) {
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.emplace_back(key);
}

void Parameters::accept(const std::vector<ParameterInfo>& infos) {
  for (const auto& info : infos) accept(info.name);
}

void Parameters::reject_unknown() const {
  for (const auto& [key, node] : table_) {
    if (std::find(known_.begin(), known_.end(), key.str()) != known_.end()) continue;
    std::string message = fmt::format("{}unknown key '{}' in [{}]", location_of(node), key.str(), section_);
    if (auto near = closest_match(key.str(), known_); !near.empty())
      message += fmt::format("; did you mean '{}'?", near);
    else if (!known_.empty())
      message += fmt::format(" (known keys: {})", fmt::join(known_, ", "));
    throw InputError(message);
  }
}

void Parameters::forbid(const std::vector<std::string>& keys, std::string_view reason) const {
  for (const auto& key : keys)
    if (has(key)) fail(key, fmt::format("does not apply {}", reason));
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string closest_match(std::string_view word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = 0;
  for (const auto& candidate : candidates) {
    std::size_t d = edit_distance(word, candidate);
    if (best.empty() || d < best_distance) {
      best = candidate;
      best_distance = d;
    }
  }
  // A typo changes a few characters: allow up to a third of the longer word, at least 2.
  std::size_t tolerance = std::max<std::size_t>(2, std::max(word.size(), best.size()) / 3);
  return !best.empty() && best_distance <= tolerance ? best : std::string();
}

}  // namespace bodyfit
