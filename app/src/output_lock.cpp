// One run per output directory (output_lock.hpp).
#include <bodyfit/app/output_lock.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <string>
#include <system_error>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

namespace bodyfit {
namespace {

std::string contents(int fd) {
  std::string text;
  char buffer[512];
  ::lseek(fd, 0, SEEK_SET);
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0 && text.size() < 4096;) text.append(buffer, std::size_t(n));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\0')) text.pop_back();
  return text;
}

std::string owner_line() {
  char host[256] = "unknown";
  ::gethostname(host, sizeof host - 1);
  const std::time_t now = std::time(nullptr);
  char when[64] = "";
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return fmt::format("pid {} on host {}, started {}\n", ::getpid(), host, when);
}

[[noreturn]] void refuse(const std::filesystem::path& dir, const std::string& owner) {
  throw InputError(fmt::format("{} is in use by another run ({}): wait for it to end, or choose another directory with -o",
                               dir.string(), owner.empty() ? "its owner is starting" : owner));
}

}  // namespace

void OutputLock::check_free(const std::filesystem::path& dir) {
  const std::filesystem::path file = dir / kFileName;
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;  // no lock file: nobody has run here since it existed
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  const std::string owner = held ? contents(fd) : std::string();
  ::close(fd);
  if (held) refuse(dir, owner);
}

OutputLock::OutputLock(const std::filesystem::path& dir) : file_(dir / kFileName) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the output directory ({})", dir.string(), ec.message()));
  fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw IoError(fmt::format("{}: cannot create the lock file ({})", file_.string(), std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    const std::string owner = contents(fd_);
    ::close(fd_);
    fd_ = -1;
    if (error == EWOULDBLOCK) refuse(dir, owner);
    throw IoError(fmt::format("{}: cannot lock ({})", file_.string(), std::strerror(error)));
  }
  if (const std::string previous = contents(fd_); !previous.empty())
    spdlog::warn("{}: the run that held it ({}) ended without releasing it (killed?): taken over", file_.string(),
                 previous);
  const std::string line = owner_line();
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, line.data(), line.size(), 0) != ssize_t(line.size()))
    spdlog::warn("{}: cannot record the owner ({})", file_.string(), std::strerror(errno));
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  // Cleared, not removed: removing it would let a run that opened it just before lock a file that
  // no longer has a name while a third locks a new one.
  if (::ftruncate(fd_, 0) != 0) spdlog::debug("{}: cannot clear the lock file", file_.string());
  ::flock(fd_, LOCK_UN);
  ::close(fd_);
}

}  // namespace bodyfit
