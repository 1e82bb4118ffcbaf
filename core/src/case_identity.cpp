#include <bodyfit/case_identity.hpp>

#include <fmt/format.h>

#include <map>
#include <sstream>

namespace bodyfit {
namespace {

/// Every value that is not a table, by dotted key, as TOML text.
void flatten(const toml::table& table, const std::string& prefix, std::map<std::string, std::string>& out) {
  for (auto&& [key, node] : table) {
    const std::string name = prefix + std::string(key.str());
    if (const auto* child = node.as_table()) {
      flatten(*child, name + ".", out);
      continue;
    }
    if (const auto* number = node.as_floating_point()) {  // shortest: 0.05, not 0.050000000000000003
      out[name] = fmt::format("{}", number->get());
      continue;
    }
    std::ostringstream text;
    node.visit([&](const auto& value) { text << value; });
    out[name] = text.str();
  }
}

std::map<std::string, std::string> flattened(const std::string& text) {
  std::map<std::string, std::string> values;
  flatten(toml::parse(text), "", values);
  return values;
}

}  // namespace

std::string canonical_case(const toml::table& effective) {
  std::ostringstream text;
  text << effective;
  return text.str();
}

std::vector<CaseChange> case_changes(const std::string& before, const std::string& after) {
  std::vector<CaseChange> changes;
  if (before == after) return changes;
  const auto a = flattened(before), b = flattened(after);
  auto i = a.begin();
  auto j = b.begin();
  while (i != a.end() || j != b.end()) {
    if (j == b.end() || (i != a.end() && i->first < j->first)) {
      changes.push_back({i->first, i->second, ""});
      ++i;
    } else if (i == a.end() || j->first < i->first) {
      changes.push_back({j->first, "", j->second});
      ++j;
    } else {
      if (i->second != j->second) changes.push_back({i->first, i->second, j->second});
      ++i, ++j;
    }
  }
  return changes;
}

bool resume_may_change(const std::string& key) {
  return key == "time.final_time" || key == "time.iterations" || key.starts_with("output.");
}

}  // namespace bodyfit
