#include <bodyfit/atomic_file.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/fault_injection.hpp>

#include <fmt/format.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <regex>
#include <system_error>
#include <fcntl.h>
#include <unistd.h>

namespace bodyfit {

void write_atomically_at(const std::filesystem::path& target,
                         const std::function<void(const std::filesystem::path& temporary)>& write) {
  namespace fs = std::filesystem;
  static std::atomic<unsigned> counter{0};
  fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) throw write_error(target, "cannot write: directory does not exist");
  fs::path temp = dir / fmt::format(".{}.tmp{}-{}", target.filename().string(), ::getpid(), counter++);
  try {
    write(temp);
    fault_point("rename:" + target.filename().string());  // a crash between the write and the rename
    std::error_code ec;
    fs::rename(temp, target, ec);
    if (ec) throw write_error(target, "cannot rename the temporary file: " + ec.message());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
}

void write_atomically(const std::filesystem::path& target, const std::function<void(std::ostream&)>& write,
                      std::uint64_t expected_bytes) {
  // Unannounced, a write over an existing file is taken to be the size of the file it replaces (an
  // output rewritten at every step): that rename is the one that pays, a new name does not.
  std::uint64_t allocate = expected_bytes;
  if (allocate == 0) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(target, ec)) {
      const std::uintmax_t size = std::filesystem::file_size(target, ec);
      if (!ec) allocate = size;
    }
  }
  write_atomically_at(target, [&](const std::filesystem::path& temp) {
    auto mode = std::ios::binary | std::ios::trunc;
    if (allocate > 0) {
      // Linux's fallocate, not posix_fallocate: where the filesystem cannot allocate, the latter
      // writes zeros instead. Any failure (no space, a file-size limit) shows again at the write.
      const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
      if (fd >= 0) {
        if (::fallocate(fd, FALLOC_FL_KEEP_SIZE, 0, off_t(allocate)) == 0)
          mode = std::ios::binary | std::ios::in | std::ios::out;  // keep the blocks: no truncation
        ::close(fd);
      }
    }
    std::ofstream out(temp, mode);
    if (!out)
      throw write_error(target, fmt::format("cannot write in {} ({})", temp.parent_path().string(), std::strerror(errno)));
    errno = 0;  // what the failing write(2) leaves: ENOSPC, EFBIG (a file-size limit), EIO…
    write(out);
    out.flush();
    if (!out) {
      const int error = errno;
      throw write_error(target, fmt::format("write failed ({})", error ? std::strerror(error) : "disk full?"));
    }
    // Blocks allocated past what was written are given back (a truncation to the same size does).
    if (allocate > 0 && std::uint64_t(out.tellp()) < allocate) {
      std::error_code ec;
      std::filesystem::resize_file(temp, std::uint64_t(out.tellp()), ec);
    }
  });
}

bool is_atomic_temporary(const std::string& file_name) {
  static const std::regex temporary(R"(\..+\.tmp[0-9]+-[0-9]+)");
  return std::regex_match(file_name, temporary);
}

}  // namespace bodyfit
