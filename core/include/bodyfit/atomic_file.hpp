#pragma once
// Write-then-rename: the target file either keeps its old content or gets the complete new one.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>

namespace bodyfit {

/// Call `write` on a stream opened on a temporary file next to `target` (binary mode), then flush,
/// check the stream and rename it over `target`. On any failure the temporary is removed and an
/// InputError naming `target` is thrown; `target` is never left half-written.
/// `expected_bytes`, when known (a binary format's size follows from its counts), has the temporary's
/// blocks allocated before the write: renaming a file over an existing one on ext4 otherwise makes
/// the kernel allocate and start writing out the new file's blocks at the rename (~1 ms per MB).
/// Without it, a write over an existing file allocates the size of the file it replaces. It is a
/// hint: the file ends where the writer stopped, and a failed allocation changes nothing.
void write_atomically(const std::filesystem::path& target, const std::function<void(std::ostream&)>& write,
                      std::uint64_t expected_bytes = 0);
/// The same for a writer that opens the file itself (a library that writes by name): `write` creates the temporary at the
/// path it is given and throws on failure; the temporary is then renamed over `target`, or removed
/// when `write` throws.
void write_atomically_at(const std::filesystem::path& target,
                         const std::function<void(const std::filesystem::path& temporary)>& write);

/// Whether a file name is one of write_atomically's temporaries (".<target>.tmp<pid>-<n>"): one
/// that exists when no write is in progress was left by a process killed during the write.
bool is_atomic_temporary(const std::string& file_name);

}  // namespace bodyfit
