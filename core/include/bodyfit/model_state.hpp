#pragma once
// ModelState: what a velocity model keeps across a resume (times at which points were reached, objective
// histories, a step size), as a small keyed container the checkpoint stores and reads back bit-exactly.
//
//   void save_state(ModelState& s) const override {
//     s.version = 1;                       // the model's own format version
//     s.set("dt", dt_);                    // a number
//     s.set("history", objective_);        // an array of numbers
//     s.set("grid", grid_bytes);           // a string (any bytes)
//   }
//   void load_state(const ModelState& s) override {
//     if (s.version != 1) throw InputError(...);
//     dt_ = s.number("dt");                // missing or of another type: InputError naming the key
//     objective_ = s.numbers("history");
//   }
//
// Keys are kept sorted, so the encoding of a state depends only on its contents.
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace bodyfit {

class ModelState {
 public:
  using Value = std::variant<std::vector<double>, std::vector<std::int64_t>, std::string>;

  /// The model's own version of its state layout (checked by the model in load_state).
  std::uint32_t version = 0;

  void set(const std::string& key, double value) { values_[key] = std::vector<double>{value}; }
  void set(const std::string& key, std::vector<double> values) { values_[key] = std::move(values); }
  void set(const std::string& key, std::vector<std::int64_t> values) { values_[key] = std::move(values); }
  void set(const std::string& key, std::string bytes) { values_[key] = std::move(bytes); }

  bool has(const std::string& key) const { return values_.count(key) > 0; }
  bool empty() const { return values_.empty(); }
  /// A number stored with set(key, double). Throws InputError when absent or of another type.
  double number(const std::string& key) const;
  const std::vector<double>& numbers(const std::string& key) const;
  const std::vector<std::int64_t>& integers(const std::string& key) const;
  const std::string& string(const std::string& key) const;

  const std::map<std::string, Value, std::less<>>& values() const { return values_; }
  bool operator==(const ModelState&) const = default;

 private:
  std::map<std::string, Value, std::less<>> values_;
};

}  // namespace bodyfit
