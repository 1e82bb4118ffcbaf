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
/// returning `const Table*`, whose first member is a std::uint32_t version that must be `version`
/// (a module of another bodyfit is refused). Never closed: the libraries behind modules keep
/// process-wide state (registered drivers, font caches, a parallel runtime's initialisation).
namespace detail {
const void* load_module_table(const std::filesystem::path& file, const char* entry, std::uint32_t version, int flags,
                              std::string_view what, std::string& failure);
}
/// The table, or nullptr with the reason in `failure` (the same on every call: opened once).
template <class Table>
const Table* module_table(const std::filesystem::path& file, const char* entry, std::uint32_t version, int flags,
                          std::string_view what, std::string& failure) {
  static std::once_flag once;
  static const void* table = nullptr;
  static std::string why;
  std::call_once(once, [&] { table = detail::load_module_table(file, entry, version, flags, what, why); });
  failure = why;
  return static_cast<const Table*>(table);
}

}  // namespace bodyfit
