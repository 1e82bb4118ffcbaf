// A model's declarations as a reference (model_reference.hpp).
#include <bodyfit/app/model_reference.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

namespace bodyfit {
namespace {

std::string type_words(const ParameterDecl& p) {
  switch (p.type) {
    case ParameterType::Numbers: return p.size ? fmt::format("{} numbers", p.size) : "numbers";
    case ParameterType::Points: return fmt::format("points of {}", p.size);
    default: return std::string(to_string(p.type));
  }
}

std::string default_words(const ParameterDecl& p) {
  if (p.required) return "required";
  return p.default_text.empty() ? "(none)" : p.default_text;
}

std::string combine_words(const Combine& c) {
  switch (c.op) {
    case Combine::Op::Share: return fmt::format("{}: share of members", c.name);
    case Combine::Op::Mean: return fmt::format("{}: mean", c.name);
    case Combine::Op::Percentiles: return fmt::format("{}<p>: percentiles", c.name);
  }
  return c.name;
}

/// A Markdown table cell: no pipe or newline breaks the row.
std::string cell(std::string text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
  return out;
}

/// Text wrapped at `width` columns, the lines after the first indented by `indent`.
std::string wrapped(const std::string& text, std::size_t indent, std::size_t width) {
  std::string out, line;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      out += line + "\n" + std::string(indent, ' ');
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    start = end + 1;
  }
  return out + line;
}

}  // namespace

std::string accepted_values(const ParameterDecl& p) {
  if (p.type == ParameterType::Choice) return fmt::format("{}", fmt::join(p.choices, ", "));
  if (p.range.unbounded()) return "";
  return p.range.describe();
}

std::string describe_model(const PluginInfo& model, ReferenceFormat format) {
  std::string out;
  if (format == ReferenceFormat::Markdown) {
    out += fmt::format("## `{}` {}\n\n", model.name, model.version);
    if (!model.description.empty()) out += model.description + ".\n\n";
    out += fmt::format("Plugin ABI {}. `[model] name = \"{}\"`.\n\n", abi_string(model.abi), model.name);
    if (!model.parameters.empty()) {
      out += "| key | type | unit | default | accepted | meaning |\n|---|---|---|---|---|---|\n";
      for (const ParameterDecl& p : model.parameters) {
        const auto dot = p.key.rfind('.');
        const std::string key = dot == std::string::npos ? fmt::format("`{}`", p.key)
                                                         : fmt::format("`{}` ([model.{}])", p.key, p.key.substr(0, dot));
        out += fmt::format("| {} | {} | {} | {} | {} | {} |\n", key, type_words(p), cell(p.unit), cell(default_words(p)),
                           cell(accepted_values(p)), cell(p.description));
      }
      out += "\n";
    }
    if (!model.outputs.empty()) {
      out += "| output | kind | unit | meaning | ensembles |\n|---|---|---|---|---|\n";
      for (const OutputDecl& o : model.outputs) {
        std::vector<std::string> combines;
        for (const Combine& c : o.ensemble) combines.push_back(combine_words(c));
        out += fmt::format("| `{}` | {} | {} | {} | {} |\n", o.name, to_string(o.kind), cell(o.unit), cell(o.description),
                           cell(fmt::format("{}", fmt::join(combines, "; "))));
      }
      out += "\n";
    }
    return out;
  }
  out += fmt::format("{} {}  (ABI {})\n  file: {}\n", model.name, model.version, abi_string(model.abi),
                     model.file.string());
  if (!model.description.empty()) out += "  " + wrapped(model.description, 2, 98) + "\n";
  out += model.parameters.empty() ? "  parameters: none\n" : "  parameters ([model] keys; a.b is b of [model.a]):\n";
  std::size_t width = 0;
  for (const ParameterDecl& p : model.parameters) width = std::max(width, p.key.size());
  for (const ParameterDecl& p : model.parameters) {
    std::string facts = type_words(p);
    if (!p.unit.empty()) facts += ", " + p.unit;
    facts += ", default " + default_words(p);
    if (const std::string accepted = accepted_values(p); !accepted.empty()) facts += ", " + accepted;
    out += fmt::format("    {:<{}}  {}\n", p.key, width,
                       wrapped(fmt::format("{} ({})", p.description, facts), width + 6, 98 - width - 6));
  }
  if (!model.outputs.empty()) {
    out += "  outputs:\n";
    width = 0;
    for (const OutputDecl& o : model.outputs) width = std::max(width, o.name.size());
    for (const OutputDecl& o : model.outputs) {
      std::string facts = std::string(to_string(o.kind));
      if (!o.unit.empty()) facts += ", " + o.unit;
      std::vector<std::string> combines;
      for (const Combine& c : o.ensemble) combines.push_back(combine_words(c));
      if (!combines.empty()) facts += fmt::format("; ensembles: {}", fmt::join(combines, "; "));
      out += fmt::format("    {:<{}}  {}\n", o.name, width,
                         wrapped(fmt::format("{} ({})", o.description, facts), width + 6, 98 - width - 6));
    }
  }
  return out;
}

}  // namespace bodyfit
