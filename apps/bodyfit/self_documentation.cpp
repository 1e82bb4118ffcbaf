// The driver's man page and bash completion, from its CLI11 definition (self_documentation.hpp).
#include "self_documentation.hpp"

#include <fmt/format.h>

#include <sstream>

namespace bodyfit::cli {
namespace {

/// Text as roff shows it verbatim: no line starting with a control character, backslashes escaped.
std::string roff_verbatim(const std::string& text) {
  std::istringstream in(text);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    std::string escaped;
    for (char c : line) escaped += c == '\\' ? std::string("\\e") : std::string(1, c);
    if (!escaped.empty() && (escaped[0] == '.' || escaped[0] == '\'')) escaped = "\\&" + escaped;
    out += escaped + "\n";
  }
  return out;
}

std::vector<CLI::App*> commands_of(CLI::App& app) {
  std::vector<CLI::App*> commands;
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    if (!command->get_group().empty()) commands.push_back(command);
  return commands;
}

/// The long and short names of a command's options (hidden ones left out).
std::string option_words(const CLI::App& command) {
  std::string words;
  for (const CLI::Option* option : command.get_options()) {
    if (option->get_group().empty() || option->get_positional()) continue;
    for (const std::string& name : option->get_lnames()) words += " --" + name;
    for (const std::string& name : option->get_snames()) words += " -" + name;
  }
  return words.empty() ? words : words.substr(1);
}

}  // namespace

std::string man_page(CLI::App& app, const std::string& version) {
  std::string page = fmt::format(".TH BODYFIT 1 \"\" \"{}\" \"User Commands\"\n", version);
  page += ".SH NAME\nbodyfit \\- track a region moving inside a fixed triangulated surface, body-fitted\n";
  page += ".SH SYNOPSIS\n.B bodyfit\n[\\fIOPTIONS\\fR] \\fICOMMAND\\fR [\\fIARGUMENTS\\fR]\n";
  page += ".SH DESCRIPTION\n.nf\n" + roff_verbatim(app.help()) + ".fi\n";
  page += ".SH COMMANDS\n";
  for (CLI::App* command : commands_of(app)) {
    page += fmt::format(".SS bodyfit {}\n.nf\n", command->get_name());
    page += roff_verbatim(command->help()) + ".fi\n";
  }
  page += ".SH FILES\nThe example cases, their data and the example plugins are in share/bodyfit of the install "
          "prefix; the manual in share/doc/bodyfit.\n";
  page += ".SH EXIT STATUS\n0 ok, 1 bad input, 2 usage, 3 internal error, 4 velocity model failure, 5 numerical "
          "failure, 6 an output that cannot be written, 130 interrupted (resumable).\n";
  return page;
}

std::string bash_completion(CLI::App& app) {
  // Two levels: a command (run, mesh...), and the commands of a command (mesh sphere, mesh terrain).
  std::string commands, cases;
  for (CLI::App* command : commands_of(app)) {
    commands += (commands.empty() ? "" : " ") + command->get_name();
    std::string words = option_words(*command);
    for (CLI::App* sub : commands_of(*command)) {
      words = sub->get_name() + (words.empty() ? "" : " ") + words;
      cases += fmt::format("    \"{} {} \"*) words=\"{}\" ;;\n", command->get_name(), sub->get_name(), option_words(*sub));
    }
    cases += fmt::format("    \"{} \"*) words=\"{}\" ;;\n", command->get_name(), words);
  }
  return fmt::format(R"(# bash completion for bodyfit (written by `bodyfit --bash-completion`)
_bodyfit() {{
  local current=${{COMP_WORDS[COMP_CWORD]}} path="" word words
  for word in "${{COMP_WORDS[@]:1:COMP_CWORD-1}}"; do
    case $word in -*) ;; *) path="$path$word " ;; esac
  done
  case "$path" in
    "") words="{} {}" ;;
{}    *) words="" ;;
  esac
  if [[ $current == -* || -z $path ]]; then
    COMPREPLY=($(compgen -W "$words" -- "$current"))
  else
    COMPREPLY=($(compgen -W "$words" -- "$current") $(compgen -f -- "$current"))
  fi
}}
complete -o filenames -F _bodyfit bodyfit
)",
                     commands, option_words(app), cases);
}

}  // namespace bodyfit::cli
