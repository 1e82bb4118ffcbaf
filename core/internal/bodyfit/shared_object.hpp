#pragma once
// bodyfit's shared objects — the velocity-model plugins and the modules of the application library
// that hold a heavy third-party library — opened one way: found from the library that asks for them (the build tree
// and any install prefix share one layout below the library directory, and no path is compiled
// in), with an error naming the file when they cannot be.
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <string_view>

namespace bodyfit {

/// The directory of the shared object holding `address` (code or data of it); empty when it
/// cannot be told.
std::filesystem::path library_directory_of(const void* address);
/// The directory of the libbodyfit_core actually loaded.
std::filesystem::path core_library_directory();

/// dlopen(file, RTLD_NOW | flags): the handle, or an InputError "<file>: cannot load <what>: <why>".
void* open_shared_object(const std::filesystem::path& file, int flags, std::string_view what);
/// The address of `symbol` in `handle`; nullptr when it has none.
void* shared_object_symbol(void* handle, const char* symbol);

/// Opens a module once and fetches its table of entry points: `entry` is an extern "C" function
/// returning `const Table*`, whose member `version` must be `version` (a module of another bodyfit
/// is refused). Never closed: the libraries behind modules keep process-wide state (registered
/// drivers, font caches, a parallel runtime's initialisation).
namespace detail {
/// The module's `entry` symbol, or nullptr with the reason in `failure`.
void* module_entry(const std::filesystem::path& file, const char* entry, int flags, std::string_view what,
                   std::string& failure);
std::string foreign_module(const std::filesystem::path& file, std::string_view what);
}  // namespace detail
/// The table, or nullptr with the reason in `failure` (the same on every call: opened once).
template <class Table>
const Table* module_table(const std::filesystem::path& file, const char* entry, std::uint32_t version, int flags,
                          std::string_view what, std::string& failure) {
  static std::once_flag once;
  static const Table* table = nullptr;
  static std::string why;
  std::call_once(once, [&] {
    // Called through its own type: a call through another function type is undefined behaviour.
    using Entry = const Table* (*)();
    const auto function = reinterpret_cast<Entry>(detail::module_entry(file, entry, flags, what, why));
    if (!function) return;
    table = function();
    if (!table || table->version != version) table = nullptr, why = detail::foreign_module(file, what);
  });
  failure = why;
  return table;
}

}  // namespace bodyfit
