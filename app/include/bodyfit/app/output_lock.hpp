#pragma once
// An output directory is written by one run at a time. The run holds an exclusive lock (flock) on
// <dir>/.bodyfit.lock for its whole life, and writes its pid, host and start time in it; a second
// run into the same directory is refused with the owner's name. The kernel releases the lock when
// the owner dies however it dies, so a lock is never stale: a file still naming an owner that no
// longer holds it (killed before clearing it) is taken over with a message.
#include <filesystem>
#include <string>

namespace bodyfit {

class OutputLock {
 public:
  /// Lock `dir` (created if missing). InputError naming the owner when another run holds it;
  /// IoError when the lock file cannot be made.
  explicit OutputLock(const std::filesystem::path& dir);
  ~OutputLock();  ///< clears the file and releases the lock
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  /// The same refusal as the constructor's when another run holds `dir`, without making anything
  /// (a run checks it before its set-up, which writes nothing).
  static void check_free(const std::filesystem::path& dir);

  /// The lock file's name (not a run output: --overwrite leaves it).
  static constexpr const char* kFileName = ".bodyfit.lock";

 private:
  int fd_ = -1;
  std::filesystem::path file_;
};

}  // namespace bodyfit
