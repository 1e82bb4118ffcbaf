#include <bodyfit/app/case_identity.hpp>

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <fstream>
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

constexpr const char* kInputFiles = "input_files";

/// "<size> bytes, fnv1a64 <hex>" of a file's bytes; empty when it cannot be read.
std::string file_digest(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};
  std::uint64_t hash = 0xcbf29ce484222325ULL, size = 0;
  std::array<char, 1 << 16> buffer{};
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    const auto got = std::size_t(in.gcount());
    for (std::size_t i = 0; i < got; ++i) hash = (hash ^ std::uint8_t(buffer[i])) * 0x100000001b3ULL;
    size += got;
  }
  return fmt::format("{} bytes, fnv1a64 {:016x}", size, hash);
}

void collect_inputs(const toml::node& node, const std::string& key, const std::filesystem::path& base_dir,
                    toml::table& inputs) {
  if (const auto* table = node.as_table()) {
    for (auto&& [name, child] : *table) {
      const std::string child_key = key.empty() ? std::string(name.str()) : key + "." + std::string(name.str());
      if (child_key != "output") collect_inputs(child, child_key, base_dir, inputs);
    }
  } else if (const auto* array = node.as_array()) {
    for (std::size_t i = 0; i < array->size(); ++i)
      collect_inputs(*array->get(i), fmt::format("{}[{}]", key, i), base_dir, inputs);
  } else if (const auto* text = node.as_string()) {
    const std::string& value = text->get();
    if (value.empty()) return;
    std::filesystem::path file(value);
    if (file.is_relative()) file = base_dir / file;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) return;
    if (std::string digest = file_digest(file); !digest.empty()) inputs.insert(key, digest);
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
  auto parsed = [](const std::string& text, const char* which) {
    try {
      return flattened(text);
    } catch (const toml::parse_error& e) {
      throw InputError(fmt::format("the {} case is not valid TOML (line {}: {})", which, e.source().begin.line,
                                   e.description()));
    }
  };
  const auto a = parsed(before, "recorded"), b = parsed(after, "new");
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

toml::table with_input_digests(const toml::table& effective, const std::filesystem::path& base_dir) {
  toml::table inputs;
  collect_inputs(effective, "", base_dir, inputs);
  toml::table out = effective;
  if (!inputs.empty()) out.insert_or_assign(kInputFiles, std::move(inputs));
  return out;
}

bool is_input_digest(const std::string& key) { return key.starts_with(std::string(kInputFiles) + "."); }

bool resume_may_change(const std::string& key) {
  return key == "time.final_time" || key == "time.iterations" || key.starts_with("output.");
}

}  // namespace bodyfit
