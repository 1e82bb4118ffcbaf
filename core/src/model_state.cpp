#include <bodyfit/error.hpp>
#include <bodyfit/model_state.hpp>

#include <fmt/format.h>

namespace bodyfit {
namespace {

template <class T>
const T& get(const std::map<std::string, ModelState::Value, std::less<>>& values, const std::string& key,
             const char* expected) {
  auto it = values.find(key);
  if (it == values.end()) throw InputError(fmt::format("model state: no entry '{}' (the checkpoint was written by another model version?)", key));
  if (const T* value = std::get_if<T>(&it->second)) return *value;
  throw InputError(fmt::format("model state: entry '{}' is not {}", key, expected));
}

}  // namespace

double ModelState::number(const std::string& key) const {
  const auto& values = get<std::vector<double>>(values_, key, "a number");
  if (values.size() != 1) throw InputError(fmt::format("model state: entry '{}' holds {} numbers, not one", key, values.size()));
  return values.front();
}
const std::vector<double>& ModelState::numbers(const std::string& key) const {
  return get<std::vector<double>>(values_, key, "an array of numbers");
}
const std::vector<std::int64_t>& ModelState::integers(const std::string& key) const {
  return get<std::vector<std::int64_t>>(values_, key, "an array of integers");
}
const std::string& ModelState::string(const std::string& key) const { return get<std::string>(values_, key, "a string"); }

}  // namespace bodyfit
