#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <unistd.h>

namespace bodyfit {

void write_atomically(const std::filesystem::path& target, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  static std::atomic<unsigned> counter{0};
  fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw write_error(target, "cannot write: directory does not exist");
  fs::path temp = dir / fmt::format(".{}.tmp{}-{}", target.filename().string(), ::getpid(), counter++);
  try {
    {
      std::ofstream out(temp, std::ios::binary | std::ios::trunc);
      if (!out)
        throw write_error(target, fmt::format("cannot write in {} ({})", dir.string(), std::strerror(errno)));
      write(out);
      out.flush();
      if (!out) throw write_error(target, "write failed (disk full?)");
    }
    std::error_code ec;
    fs::rename(temp, target, ec);
    if (ec) throw write_error(target, "cannot rename the temporary file: " + ec.message());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
}

}  // namespace bodyfit
