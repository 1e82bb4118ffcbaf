#include <bodyfit/shared_object.hpp>

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <dlfcn.h>
#include <elf.h>

#include <cstring>
#include <fstream>
#include <system_error>
#include <vector>

namespace bodyfit {
namespace {

#if defined(__x86_64__)
constexpr int kMachine = EM_X86_64;
#elif defined(__aarch64__)
constexpr int kMachine = EM_AARCH64;
#else
constexpr int kMachine = -1;  // not checked
#endif

/// Why `file` cannot be a shared object for this process ("" when it can): the dynamic loader maps
/// what the headers say, so a truncated file or one made for another machine dies of SIGBUS or
/// worse inside dlopen instead of failing.
std::string elf_problem(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return "not a regular file";
  const auto size = std::uint64_t(std::filesystem::file_size(file, ec));
  if (ec) return "its size cannot be read";
  std::ifstream in(file, std::ios::binary);
  Elf64_Ehdr header{};
  if (size < sizeof header || !in.read(reinterpret_cast<char*>(&header), sizeof header))
    return fmt::format("not an ELF shared object ({} bytes)", size);
  if (std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0) return "not an ELF file";
  if (header.e_ident[EI_CLASS] != ELFCLASS64 || header.e_ident[EI_DATA] != ELFDATA2LSB)
    return "an ELF file of another word size or byte order";
  if (header.e_type != ET_DYN) return "an ELF file that is not a shared object";
  if (kMachine >= 0 && header.e_machine != kMachine)
    return fmt::format("a shared object for another processor (ELF machine {})", header.e_machine);
  auto beyond = [&](std::uint64_t offset, std::uint64_t length) { return offset > size || length > size - offset; };
  if (header.e_phentsize != sizeof(Elf64_Phdr) || beyond(header.e_phoff, std::uint64_t(header.e_phnum) * sizeof(Elf64_Phdr)))
    return fmt::format("a damaged or truncated ELF file ({} bytes: its program headers lie beyond)", size);
  if (header.e_shoff != 0 && beyond(header.e_shoff, std::uint64_t(header.e_shnum) * header.e_shentsize))
    return fmt::format("a truncated ELF file ({} bytes; its section headers end at byte {})", size,
                       header.e_shoff + std::uint64_t(header.e_shnum) * header.e_shentsize);
  std::vector<Elf64_Phdr> segments(header.e_phnum);
  in.seekg(std::streamoff(header.e_phoff));
  if (!in.read(reinterpret_cast<char*>(segments.data()), std::streamsize(segments.size() * sizeof(Elf64_Phdr))))
    return "a damaged ELF file (its program headers cannot be read)";
  for (const Elf64_Phdr& segment : segments)
    if (segment.p_type == PT_LOAD && beyond(segment.p_offset, segment.p_filesz))
      return fmt::format("a truncated ELF file ({} bytes; a segment ends at byte {})", size,
                         segment.p_offset + segment.p_filesz);
  return {};
}

}  // namespace

std::filesystem::path library_directory_of(const void* address) {
  Dl_info info;
  if (!dladdr(address, &info) || !info.dli_fname) return {};
  std::error_code ec;
  std::filesystem::path library = std::filesystem::weakly_canonical(std::filesystem::path(info.dli_fname), ec);
  if (ec) return {};
  return library.parent_path();
}

std::filesystem::path core_library_directory() {
  static const char anchor = 0;  // an object of this library: dladdr names the file it came from
  return library_directory_of(&anchor);
}

void* open_shared_object(const std::filesystem::path& file, int flags, std::string_view what) {
  if (const std::string problem = elf_problem(file); !problem.empty())
    throw file_error(file, fmt::format("cannot load {}: {}", what, problem));
  dlerror();
  void* handle = dlopen(file.c_str(), RTLD_NOW | flags);
  if (!handle) {
    const char* reason = dlerror();
    throw file_error(file, fmt::format("cannot load {}: {}", what, reason ? reason : "unknown dynamic-loader error"));
  }
  return handle;
}

void* shared_object_symbol(void* handle, const char* symbol) {
  dlerror();
  return dlsym(handle, symbol);
}

namespace detail {

void* module_entry(const std::filesystem::path& file, const char* entry, int flags, std::string_view what,
                   std::string& failure) {
  void* handle = dlopen(file.c_str(), RTLD_NOW | flags);
  if (!handle) {
    const char* reason = dlerror();
    failure = fmt::format("cannot load bodyfit's {} {}: {}", what, file.string(), reason ? reason : "?");
    return nullptr;
  }
  void* function = shared_object_symbol(handle, entry);
  if (!function) failure = foreign_module(file, what);
  return function;
}

std::string foreign_module(const std::filesystem::path& file, std::string_view what) {
  return fmt::format("{} is not the {} of this bodyfit (reinstall bodyfit)", file.string(), what);
}

}  // namespace detail
}  // namespace bodyfit
