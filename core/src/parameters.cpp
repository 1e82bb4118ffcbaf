#include <bodyfit/parameters.hpp>

#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

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

bool Range::unbounded() const { return std::isinf(min) && min < 0 && std::isinf(max) && max > 0; }

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

// ---- declarations --------------------------------------------------------------------------------

std::string_view to_string(ParameterType type) {
  switch (type) {
    case ParameterType::Number: return "number";
    case ParameterType::Integer: return "integer";
    case ParameterType::Boolean: return "boolean";
    case ParameterType::String: return "string";
    case ParameterType::Choice: return "choice";
    case ParameterType::Path: return "file";
    case ParameterType::Numbers: return "numbers";
    case ParameterType::Points: return "points";
    case ParameterType::Strings: return "strings";
    case ParameterType::Table: return "table";
  }
  return "?";
}

namespace {
ParameterDecl make_decl(std::string key, ParameterType type, std::string unit, std::string description) {
  ParameterDecl d;
  d.key = std::move(key);
  d.type = type;
  d.unit = std::move(unit);
  d.description = std::move(description);
  return d;
}

std::string toml_text(double value) {
  std::string text = fmt::format("{}", value);
  if (std::isfinite(value) && text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}
}  // namespace

ParameterDecl ParameterDecl::number(std::string key, std::string unit, std::string description) {
  return make_decl(std::move(key), ParameterType::Number, std::move(unit), std::move(description));
}
ParameterDecl ParameterDecl::integer(std::string key, std::string unit, std::string description) {
  return make_decl(std::move(key), ParameterType::Integer, std::move(unit), std::move(description));
}
ParameterDecl ParameterDecl::boolean(std::string key, std::string description) {
  return make_decl(std::move(key), ParameterType::Boolean, "", std::move(description));
}
ParameterDecl ParameterDecl::string(std::string key, std::string description) {
  return make_decl(std::move(key), ParameterType::String, "", std::move(description));
}
ParameterDecl ParameterDecl::choice(std::string key, std::vector<std::string> choices, std::string description) {
  ParameterDecl d = make_decl(std::move(key), ParameterType::Choice, "", std::move(description));
  d.choices = std::move(choices);
  return d;
}
ParameterDecl ParameterDecl::path(std::string key, std::string description) {
  return make_decl(std::move(key), ParameterType::Path, "", std::move(description));
}
ParameterDecl ParameterDecl::numbers(std::string key, std::size_t size, std::string unit, std::string description) {
  ParameterDecl d = make_decl(std::move(key), ParameterType::Numbers, std::move(unit), std::move(description));
  d.size = size;
  return d;
}
ParameterDecl ParameterDecl::points(std::string key, std::size_t size, std::string unit, std::string description) {
  ParameterDecl d = make_decl(std::move(key), ParameterType::Points, std::move(unit), std::move(description));
  d.size = size;
  return d;
}
ParameterDecl ParameterDecl::strings(std::string key, std::string description) {
  return make_decl(std::move(key), ParameterType::Strings, "", std::move(description));
}
ParameterDecl ParameterDecl::table(std::string key, std::string description) {
  return make_decl(std::move(key), ParameterType::Table, "", std::move(description));
}

ParameterDecl ParameterDecl::fallback(double value) const {
  ParameterDecl d = *this;
  d.number_default = value;
  d.default_text = toml_text(value);
  return d;
}
ParameterDecl ParameterDecl::fallback(std::int64_t value) const {
  ParameterDecl d = *this;
  d.integer_default = value;
  d.number_default = double(value);
  d.default_text = fmt::format("{}", value);
  return d;
}
ParameterDecl ParameterDecl::fallback(bool value) const {
  ParameterDecl d = *this;
  d.boolean_default = value;
  d.default_text = value ? "true" : "false";
  return d;
}
ParameterDecl ParameterDecl::fallback(const char* value) const {
  ParameterDecl d = *this;
  d.string_default = value;
  std::ostringstream text;
  text << toml::value<std::string>(value);
  d.default_text = text.str();
  return d;
}
ParameterDecl ParameterDecl::fallback(std::vector<double> values) const {
  ParameterDecl d = *this;
  std::vector<std::string> texts;
  for (double v : values) texts.push_back(fmt::format("{}", v));
  d.default_text = fmt::format("[{}]", fmt::join(texts, ", "));
  d.numbers_default = std::move(values);
  return d;
}
ParameterDecl ParameterDecl::computed(std::string phrase) const {
  ParameterDecl d = *this;
  d.default_text = "(" + std::move(phrase) + ")";
  return d;
}
ParameterDecl ParameterDecl::within(Range accepted) const {
  ParameterDecl d = *this;
  d.range = accepted;
  return d;
}
ParameterDecl ParameterDecl::positive() const { return within({.min = 0, .min_exclusive = true}); }
ParameterDecl ParameterDecl::at_least(double min) const { return within({.min = min}); }
ParameterDecl ParameterDecl::require() const {
  ParameterDecl d = *this;
  d.required = true;
  return d;
}

// ---- reading -------------------------------------------------------------------------------------

Parameters::Parameters(const toml::table& table, std::shared_ptr<const std::vector<ParameterDecl>> declarations,
                       std::string section, std::string prefix)
    : table_(table), declarations_(std::move(declarations)), section_(std::move(section)), prefix_(std::move(prefix)) {}

Parameters::Parameters(const toml::table& table, std::vector<ParameterDecl> declarations, std::string section)
    : Parameters(table, std::make_shared<const std::vector<ParameterDecl>>(std::move(declarations)), std::move(section),
                 "") {}

Parameters::Parameters(const toml::table& table, std::string section) : Parameters(table, nullptr, std::move(section), "") {}

Parameters::Parameters(const toml::table* table, std::string section)
    : Parameters(table ? *table : empty_table(), std::move(section)) {}

Parameters::~Parameters() = default;

const std::vector<ParameterDecl>& Parameters::declarations() const {
  static const std::vector<ParameterDecl> none;
  return declarations_ ? *declarations_ : none;
}

void Parameters::declare(std::vector<ParameterDecl> more) {
  auto all = std::make_shared<std::vector<ParameterDecl>>(declarations());
  for (ParameterDecl& d : more) {
    d.key = prefix_ + d.key;
    if (std::any_of(all->begin(), all->end(), [&](const ParameterDecl& x) { return x.key == d.key; }))
      throw std::logic_error(fmt::format("[{}] {}: declared twice", section_, d.key));
    all->push_back(std::move(d));
  }
  declarations_ = std::move(all);
}

bool Parameters::has(std::string_view key) const { return table_.contains(key); }

bool Parameters::is_table(std::string_view key) const {
  const toml::node* node = table_.get(key);
  return node && node->is_table();
}

const ParameterDecl* Parameters::declaration(std::string_view key) const {
  if (!declarations_) return nullptr;
  const std::string full = prefix_ + std::string(key);
  for (const ParameterDecl& d : *declarations_)
    if (d.key == full) return &d;
  return nullptr;
}

const toml::node* Parameters::find(std::string_view key) {
  accept(key);
  return table_.get(key);
}

const ParameterDecl* Parameters::declared(std::string_view key, std::initializer_list<ParameterType> types) const {
  if (!declarations_) return nullptr;
  const std::string full = prefix_ + std::string(key);
  for (const ParameterDecl& d : *declarations_) {
    if (d.key != full) continue;
    if (std::find(types.begin(), types.end(), d.type) == types.end())
      throw std::logic_error(fmt::format("[{}] {}: read as another type than its declaration ({})", section_, key,
                                         to_string(d.type)));
    return &d;
  }
  throw std::logic_error(fmt::format("[{}] {}: read, but not declared among the model's parameters", section_, key));
}

void Parameters::fail(std::string_view key, const std::string& what) const {
  const toml::node* node = table_.get(key);
  throw InputError(fmt::format("{}[{}] {}: {}", location_of(node ? *node : table_), section_, key, what));
}

void Parameters::fail(const std::string& what) const {
  throw InputError(fmt::format("{}[{}] {}", location_of(table_), section_, what));
}

namespace {
/// The range a read checks: the call's, else the declaration's.
Range range_of(const ParameterDecl* d, const Range& given) { return d && given.unbounded() ? d->range : given; }
}  // namespace

double Parameters::number(std::string_view key, double fallback, Range range) {
  const ParameterDecl* d = declared(key, {ParameterType::Number, ParameterType::Integer});
  range = range_of(d, range);
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = as_number(*node);
  if (!value) fail(key, fmt::format("expected a number, got {}", type_name(*node)));
  if (auto why = refusal(*value, range); !why.empty()) fail(key, why);
  return *value;
}

double Parameters::required_number(std::string_view key, Range range) {
  range = range_of(declared(key, {ParameterType::Number, ParameterType::Integer}), range);
  if (!has(key)) fail(key, "required (a number in " + range.describe() + ")");
  return number(key, 0.0, range);
}

std::int64_t Parameters::integer(std::string_view key, std::int64_t fallback, std::int64_t min, std::int64_t max) {
  if (const ParameterDecl* d = declared(key, {ParameterType::Integer}); d && !d->range.unbounded()) {
    using limits = std::numeric_limits<std::int64_t>;
    if (min == limits::min() && std::isfinite(d->range.min)) min = std::int64_t(std::ceil(d->range.min));
    if (max == limits::max() && std::isfinite(d->range.max)) max = std::int64_t(std::floor(d->range.max));
  }
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = node->as_integer();
  if (!value) fail(key, fmt::format("expected an integer, got {}", type_name(*node)));
  std::int64_t v = value->get();
  if (v < min || v > max) fail(key, fmt::format("{} is out of range {}", v, describe_integers(min, max)));
  return v;
}

bool Parameters::boolean(std::string_view key, bool fallback) {
  declared(key, {ParameterType::Boolean});
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = node->as_boolean();
  if (!value) fail(key, fmt::format("expected true or false, got {}", type_name(*node)));
  return value->get();
}

std::string Parameters::string(std::string_view key, std::string fallback) {
  declared(key, {ParameterType::String, ParameterType::Choice, ParameterType::Path});
  const toml::node* node = find(key);
  if (!node) return fallback;
  auto value = node->as_string();
  if (!value) fail(key, fmt::format("expected a string, got {}", type_name(*node)));
  return value->get();
}

std::filesystem::path Parameters::path(std::string_view key, std::string fallback) {
  return path(key, std::move(fallback), std::filesystem::path());
}

std::filesystem::path Parameters::path(std::string_view key, std::string fallback,
                                       const std::filesystem::path& sourceless) {
  declared(key, {ParameterType::Path});
  const bool present = has(key);
  std::string text = string(key, std::move(fallback));
  if (!present || text.empty()) return text;
  std::filesystem::path name(text);
  if (name.is_absolute()) return name.lexically_normal();
  const auto& source = table_.get(key)->source();
  // toml++ keeps the name given to parse_file, relative to the working directory of that call.
  std::filesystem::path base = source.path ? std::filesystem::path(*source.path).parent_path() : sourceless;
  return std::filesystem::absolute(base / name).lexically_normal();
}

std::string Parameters::choice(std::string_view key, std::string fallback, const std::vector<std::string>& allowed) {
  const ParameterDecl* d = declared(key, {ParameterType::Choice});
  const std::vector<std::string>& choices = d && allowed.empty() ? d->choices : allowed;
  std::string value = string(key, std::move(fallback));
  if (std::find(choices.begin(), choices.end(), value) == choices.end()) {
    std::string hint;
    if (auto near = closest_match(value, choices); !near.empty()) hint = fmt::format("; did you mean '{}'?", near);
    fail(key, fmt::format("'{}' is not one of {}{}", value, fmt::join(choices, ", "), hint));
  }
  return value;
}

std::vector<double> Parameters::numbers(std::string_view key, std::vector<double> fallback,
                                        std::optional<std::size_t> size, Range range) {
  const ParameterDecl* d = declared(key, {ParameterType::Numbers});
  range = range_of(d, range);
  if (d && !size && d->size > 0) size = d->size;
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
  range = range_of(declared(key, {ParameterType::Points}), range);
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

// ---- reading through the declaration ------------------------------------------------------------

namespace {
[[noreturn]] void no_declarations(std::string_view section, std::string_view key) {
  throw std::logic_error(fmt::format("[{}] {}: read without a fallback, but the table has no declarations", section, key));
}
}  // namespace

double Parameters::number(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Number, ParameterType::Integer});
  if (!d) no_declarations(section_, key);
  if (!has(key) && (d->required || !d->number_default)) return required_number(key);
  return number(key, d->number_default.value_or(0.0));
}

std::int64_t Parameters::integer(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Integer});
  if (!d) no_declarations(section_, key);
  if (!has(key) && (d->required || !d->integer_default)) fail(key, "required (an integer)");
  return integer(key, d->integer_default.value_or(0));
}

bool Parameters::boolean(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Boolean});
  if (!d) no_declarations(section_, key);
  if (!has(key) && (d->required || !d->boolean_default)) fail(key, "required (true or false)");
  return boolean(key, d->boolean_default.value_or(false));
}

std::string Parameters::string(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::String, ParameterType::Choice, ParameterType::Path});
  if (!d) return string(key, "");
  if (!has(key) && d->required) fail(key, "required (a string)");
  return string(key, d->string_default.value_or(""));
}

std::string Parameters::choice(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Choice});
  if (!d) no_declarations(section_, key);
  if (!has(key) && (d->required || !d->string_default))
    fail(key, fmt::format("required (one of {})", fmt::join(d->choices, ", ")));
  return choice(key, d->string_default.value_or(""), {});
}

std::filesystem::path Parameters::path(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Path});
  if (!d) return path(key, "");
  if (!has(key) && d->required) fail(key, "required (a file name)");
  return path(key, d->string_default.value_or(""));
}

std::vector<double> Parameters::numbers(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Numbers});
  if (!d) no_declarations(section_, key);
  if (!has(key) && d->required) fail(key, "required (an array of numbers)");
  return numbers(key, d->numbers_default.value_or(std::vector<double>{}));
}

std::vector<std::vector<double>> Parameters::points(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Points});
  if (!d) no_declarations(section_, key);
  if (!has(key) && d->required) fail(key, fmt::format("required (an array of arrays of {} numbers)", d->size));
  return number_arrays(key, d->size);
}

std::vector<std::string> Parameters::strings(std::string_view key) {
  const ParameterDecl* d = declared(key, {ParameterType::Strings});
  const toml::node* node = find(key);
  if (!node) {
    if (d && d->required) fail(key, "required (an array of strings)");
    return {};
  }
  auto array = node->as_array();
  if (!array) fail(key, fmt::format("expected an array of strings, got {}", type_name(*node)));
  std::vector<std::string> values;
  for (const auto& element : *array) {
    auto value = element.as_string();
    if (!value) fail(key, fmt::format("expected an array of strings, found {} in it", type_name(element)));
    values.push_back(value->get());
  }
  return values;
}

const toml::table* Parameters::table(std::string_view key) {
  declared(key, {ParameterType::Table});
  const toml::node* node = find(key);
  if (!node) return nullptr;
  auto t = node->as_table();
  if (!t) fail(key, fmt::format("expected a table, got {}", type_name(*node)));
  return t;
}

Parameters& Parameters::section(std::string_view key) {
  if (auto it = sections_.find(key); it != sections_.end()) return *it->second;
  if (declarations_) {
    const std::string prefix = prefix_ + std::string(key) + ".";
    if (std::none_of(declarations_->begin(), declarations_->end(),
                     [&](const ParameterDecl& d) { return d.key.starts_with(prefix); }))
      throw std::logic_error(fmt::format("[{}] {}: read as a section, but no parameter is declared in it", section_, key));
  }
  const toml::node* node = find(key);
  const toml::table* t = node ? node->as_table() : nullptr;
  if (node && !t) fail(key, fmt::format("expected a table, got {}", type_name(*node)));
  auto child = std::unique_ptr<Parameters>(new Parameters(t ? *t : empty_table(), declarations_,
                                                          section_ + "." + std::string(key),
                                                          prefix_ + std::string(key) + "."));
  return *sections_.emplace(std::string(key), std::move(child)).first->second;
}

void Parameters::accept(std::string_view key) {
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.emplace_back(key);
}

void Parameters::not_used(std::string_view key, std::string reason) {
  const std::vector<std::string> keys = known_keys();
  if (declarations_ && std::find(keys.begin(), keys.end(), key) == keys.end())
    throw std::logic_error(fmt::format("[{}] {}: not_used() of a key that is not declared", section_, key));
  not_used_[std::string(key)] = std::move(reason);
}

std::vector<std::string> Parameters::known_keys() const {
  if (!declarations_) return known_;
  std::vector<std::string> keys;
  for (const ParameterDecl& d : *declarations_) {
    if (!d.key.starts_with(prefix_)) continue;
    std::string key = d.key.substr(prefix_.size());
    key = key.substr(0, key.find('.'));
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
  }
  return keys;
}

void Parameters::reject_unknown() const {
  const std::vector<std::string> known = known_keys();
  for (const auto& [key, node] : table_) {
    if (std::find(known_.begin(), known_.end(), key.str()) != known_.end()) continue;
    std::string message = fmt::format("{}unknown key '{}' in [{}]", location_of(node), key.str(), section_);
    if (auto near = closest_match(key.str(), known); !near.empty())
      message += fmt::format("; did you mean '{}'?", near);
    else if (!known.empty())
      message += fmt::format(" (known keys: {})", fmt::join(known, ", "));
    throw InputError(message);
  }
}

void Parameters::check_consumed() const {
  const std::vector<std::string> known = known_keys();
  for (const auto& [k, node] : table_) {
    const std::string key(k.str());
    if (std::find(known_.begin(), known_.end(), key) != known_.end()) {
      if (auto it = sections_.find(key); it != sections_.end()) it->second->check_consumed();
      continue;
    }
    if (std::find(known.begin(), known.end(), key) != known.end()) {  // declared, but not read
      if (auto why = not_used_.find(key); why != not_used_.end())
        throw InputError(fmt::format("{}[{}] {} is not used: {}", location_of(node), section_, key, why->second));
      throw InputError(fmt::format("{}[{}] {} is set but not used with these settings (remove it)", location_of(node),
                                   section_, key));
    }
    reject_unknown();  // the first unknown key, with a suggestion
  }
}

std::vector<std::string> Parameters::consumed() const {
  std::vector<std::string> keys;
  for (const auto& key : known_) {
    if (!table_.contains(key)) continue;
    if (auto it = sections_.find(key); it != sections_.end())
      for (const auto& inner : it->second->consumed()) keys.push_back(key + "." + inner);
    else
      keys.push_back(key);
  }
  return keys;
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
