#include "mmg_spellings.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <iterator>

namespace bodyfit::cli {
namespace {

/// MMG options bodyfit has no equivalent for, with advice when there is some.
struct Unsupported {
  const char* spelling;
  const char* advice;
};
constexpr Unsupported kUnsupported[] = {
    {"-hsiz", "give --hmin and --hmax the same value"},
    {"-met", "size maps are not supported: give --hmin, --hmax and --hausd"},
    {"-A", "anisotropic remeshing is not supported"},
    {"-ar", "give the ridge angle with --angle"},
    {"-noinsert", "no equivalent (bodyfit always inserts and collapses as the sizes require)"},
    {"-noswap", "no equivalent"},
    {"-nomove", "no equivalent"},
    {"-nosurf", "no equivalent (the surface is always kept: vertices are projected onto it)"},
    {"-nreg", "no equivalent"},
    {"-xreg", "no equivalent"},
    {"-optim", "no equivalent (give the sizes with --hmin/--hmax)"},
    {"-rmc", "give the size of the specks to remove with `discretize --speck`"},
    {"-rn", "no equivalent"},
    {"-iso", "use `bodyfit discretize` (MMG's -ls)"},
    {"-isoref", "no equivalent"},
    {"-keep-ref", "no equivalent (refs are always kept)"},
    {"-default", "no equivalent"},
    {"-lag", "use `bodyfit advect`"},
    {"-octree", "no equivalent"},
    {"-nsd", "no equivalent"},
    {"-opnbdy", "no equivalent"},
    {"-m", "no equivalent"},
    {"-d", "no equivalent"},
};

bool is_number(const std::string& s, double* value) {
  double v = 0;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) return false;
  if (value) *value = v;
  return true;
}

}  // namespace

Translation translate_mmg_spellings(std::vector<std::string> arguments, const std::vector<std::string>& subcommands) {
  Translation t;
  auto command_at = std::find_if(arguments.begin(), arguments.end(), [&](const std::string& a) {
    return std::find(subcommands.begin(), subcommands.end(), a) != subcommands.end();
  });
  const std::string command = command_at == arguments.end() ? std::string() : *command_at;
  const bool discretize = command == "discretize", remesh = command == "remesh";
  auto refuse = [&](const std::string& message) {
    t.error = message;
    return t;
  };
  std::vector<std::string>& out = t.arguments;
  out.assign(arguments.begin(), command_at == arguments.end() ? arguments.end() : command_at + 1);
  if (command_at == arguments.end()) return t;
  for (auto it = command_at + 1; it != arguments.end(); ++it) {
    std::string a = *it;
    // MMG's -hmax=0.1: the option and its value (CLI11 would read -h, help, and exit 0).
    if (const auto eq = a.find('='); a.size() > 2 && a[0] == '-' && a[1] != '-' && eq != std::string::npos) {
      const std::string name = a.substr(0, eq);
      if (name == "-hmin" || name == "-hmax" || name == "-hausd" || name == "-hgrad") {
        if (!discretize && !remesh)
          return refuse(fmt::format("{} is MMG's spelling, for `bodyfit discretize` and `bodyfit remesh`; `bodyfit {}` "
                                    "has no such option (see bodyfit {} --help)",
                                    name, command, command));
        out.push_back("-" + a);  // --hmax=0.1
        continue;
      }
    }
    const bool sizes = a == "-hmin" || a == "-hmax" || a == "-hausd" || a == "-hgrad";
    const bool mmg = sizes || a == "-in" || a == "-out" || a == "-sol" || a == "-ls" || a == "-nr";
    if (mmg && !discretize && !remesh)
      return refuse(fmt::format("{} is MMG's spelling, for `bodyfit discretize` and `bodyfit remesh`; `bodyfit {}` "
                                "has no such option (see bodyfit {} --help)",
                                a, command, command));
    if (sizes) {
      out.push_back("-" + a);  // --hmax
    } else if (a == "-in") {
      if (it + 1 == arguments.end()) return refuse("-in (MMG's spelling of the input mesh): the file name is missing");
      out.push_back(*++it);  // the positional input
    } else if (a == "-out") {
      out.push_back("-o");
    } else if (a == "-nr") {
      out.push_back("--angle");
      out.push_back("0");
    } else if (a == "-sol") {
      if (remesh)
        return refuse("-sol: `bodyfit remesh` takes no size map (MMG's -sol); give --hmin, --hmax and --hausd, or cut "
                      "a level set with `bodyfit discretize --phi`");
      out.push_back("--phi");
    } else if (a == "-ls") {
      if (remesh)
        return refuse("-ls: `bodyfit remesh` does not cut a level set; use `bodyfit discretize IN --phi PHI.sol -o OUT` "
                      "(MMG's -ls: it cuts the zero level set, then remeshes)");
      double value = 0;
      if (it + 1 != arguments.end() && is_number(*(it + 1), &value)) {
        if (value != 0)
          return refuse(fmt::format("-ls {}: `bodyfit discretize` cuts the level set 0 only; subtract {} from the "
                                    "values of --phi first",
                                    *(it + 1), *(it + 1)));
        ++it;  // -ls 0: the default
      }
      // -ls alone: what discretize does anyway.
    } else if (auto u = std::find_if(std::begin(kUnsupported), std::end(kUnsupported),
                                     [&](const Unsupported& x) { return a == x.spelling; });
               u != std::end(kUnsupported) && (discretize || remesh)) {
      return refuse(fmt::format("{} (an MMG option) is not supported by `bodyfit {}`: {}", a, command, u->advice));
    } else if (a.size() > 2 && a[0] == '-' && a[1] != '-' && !is_number(a, nullptr) &&
               !std::isdigit(static_cast<unsigned char>(a[1])) && a[1] != '.') {  // -5x3: a value
      // A single dash before a word is not an option of bodyfit's (its long options take two): CLI11
      // would read it as a group of one-letter flags, -help… among them.
      return refuse(fmt::format("{}: unknown option (bodyfit's long options take two dashes: -{}; see bodyfit {} --help)",
                                a, a, command));
    } else {
      out.push_back(a);
    }
  }
  return t;
}

}  // namespace bodyfit::cli
