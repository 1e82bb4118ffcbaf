#pragma once
// The command line of a bench program: its options by name, --help / -h, and errors.
//
//   bench::Arguments args("bench_x", "usage: bench_x [--h 0.1,0.05] [-o out.csv] [--p1]\n  ...\n");
//   args.option("--h", hs);          // int, double, std::size_t, std::string, path, or a comma list of those
//   args.option("-o", csv_path);
//   args.flag("--p1", [&] { options.gradient_correction = false; });
//   args.option("--solvers", [&](const std::string& value) { ... });  // anything else
//   args.positional("out.csv", csv_path);  // only where the usage documents one
//   args.parse(argc, argv);
//
// parse() prints the usage and exits 0 on --help or -h, before anything is read or written. An
// unknown option, a missing or malformed value (the whole text must be a number), or a positional
// argument the program does not take prints "<program>: <what>" and the usage to stderr and exits
// with code 2; so does args.fail(message), for checks after parsing.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace bench {

class Arguments {
 public:
  Arguments(std::string program, std::string usage) : program_(std::move(program)), usage_(std::move(usage)) {}

  /// An option that takes the next argument as its value, handed to `action`.
  void option(const std::string& name, std::function<void(const std::string&)> action) {
    options_.push_back({name, true, std::move(action)});
  }
  /// An option whose value is converted to `target`'s type (a vector: comma-separated values).
  template <class T>
  void option(const std::string& name, T& target) {
    option(name, [&target](const std::string& value) { target = convert<T>(value); });
  }
  /// An option without a value.
  void flag(const std::string& name, std::function<void()> action) {
    options_.push_back({name, false, [action = std::move(action)](const std::string&) { action(); }});
  }
  void flag(const std::string& name, bool& target) {
    flag(name, [&target] { target = true; });
  }
  /// The next positional argument (in the order of declaration; each optional).
  template <class T>
  void positional(const std::string& name, T& target) {
    positionals_.push_back({name, false, [&target](const std::string& value) { target = convert<T>(value); }});
  }
  /// Every remaining positional argument.
  template <class T>
  void positionals(const std::string& name, std::vector<T>& target) {
    rest_ = {name, false, [&target](const std::string& value) { target.push_back(convert<T>(value)); }};
  }

  void parse(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
      if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
        std::fputs(usage_.c_str(), stdout);
        std::exit(0);
      }
    }
    std::size_t next_positional = 0;
    for (int i = 1; i < argc; ++i) {
      const std::string word = argv[i];
      const Spec* spec = nullptr;
      if (word.size() > 1 && word[0] == '-') {
        for (const auto& s : options_)
          if (s.name == word) spec = &s;
        if (!spec) fail("unknown option '" + word + "'");
      } else if (next_positional < positionals_.size()) {
        spec = &positionals_[next_positional++];
      } else if (rest_.action) {
        spec = &rest_;
      } else {
        fail("unexpected argument '" + word + "'");
      }
      std::string value = spec->takes_value ? "" : word;
      if (spec->takes_value) {
        if (i + 1 >= argc) fail(word + " needs a value");
        value = argv[++i];
      }
      try {
        spec->action(value);
      } catch (const std::exception& e) {
        fail(spec->name + " '" + value + "': " + e.what());
      }
    }
  }

  /// Prints the error and the usage to stderr and exits with code 2.
  [[noreturn]] void fail(const std::string& message) const {
    std::fprintf(stderr, "%s: %s\n%s", program_.c_str(), message.c_str(), usage_.c_str());
    std::exit(2);
  }

 private:
  struct Spec {
    std::string name;
    bool takes_value = false;
    std::function<void(const std::string&)> action;
  };

  template <class T>
  static T convert(const std::string& text) {
    if constexpr (std::is_same_v<T, std::string> || std::is_same_v<T, std::filesystem::path>) {
      return T(text);
    } else if constexpr (std::is_arithmetic_v<T>) {
      std::istringstream in(text);
      T value{};
      if (text.empty() || (std::is_unsigned_v<T> && text[0] == '-') || !(in >> value) || !in.eof())
        throw std::invalid_argument("not a number");
      return value;
    } else {  // a std::vector: comma-separated values
      T values;
      std::stringstream list(text);
      for (std::string item; std::getline(list, item, ',');)
        values.push_back(convert<typename T::value_type>(item));
      if (values.empty()) throw std::invalid_argument("empty list");
      return values;
    }
  }

  std::string program_, usage_;
  std::vector<Spec> options_, positionals_;
  Spec rest_;
};

}  // namespace bench
