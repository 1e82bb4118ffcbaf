#pragma once
// A text section's records read by every thread when they are one per line, as every writer we
// know writes them (io_medit.cpp, io_sol.cpp).
#include "medit_format.hpp"

#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

namespace bodyfit::io_detail {

/// Below this many records one thread reads a section as fast.
constexpr std::int64_t kParallelRecords = 16384;

/// The line breaks in [from, to).
std::int64_t count_line_breaks(const char* from, const char* to);

/// The first `n` lines of `text` cut into shares for the threads: where each share starts and its
/// first line's index; the last entry is the end of the n-th line (after its break) and n.
struct LineShare {
  const char* at;
  std::int64_t first;
};
/// Empty when `text` has fewer than n line breaks.
std::vector<LineShare> share_lines(std::string_view text, std::int64_t n, int shares);

/// Reads the `n` records that follow in `in` with every thread, when they are one per line: each
/// share of the lines gets a scanner of its own, numbered from its first line, and
/// `record(scanner, i)` reads record i. Anything else — a record over two lines, a comment or a
/// blank line among them, a number that does not parse — returns false with `in` where it was: the
/// one-thread loop then reads the section and says what is wrong, and where.
template <class Record>
bool read_lines_in_parallel(TextScanner& in, std::int64_t n, const std::filesystem::path& file, Record&& record) {
  const int threads = tbb::this_task_arena::max_concurrency();
  if (n < kParallelRecords || threads < 2) return false;
  const long first_line = in.line();
  const std::vector<LineShare> shares = share_lines(in.rest(), n, threads);
  if (shares.empty()) return false;
  std::atomic<bool> regular = true;
  tbb::parallel_for(std::size_t(0), shares.size() - 1, [&](std::size_t t) {
    const LineShare from = shares[t], to = shares[t + 1];
    TextScanner share(std::string_view(from.at, std::size_t(to.at - from.at)), file, first_line + long(from.first));
    try {
      for (std::int64_t i = from.first; i < to.first && regular.load(std::memory_order_relaxed); ++i) {
        if (!share.skip_blank() || share.line() != first_line + long(i)) {
          regular = false;
          return;
        }
        record(share, i);
      }
      if (share.skip_blank()) regular = false;  // more on its lines than its records
    } catch (const InputError&) {
      regular = false;
    }
  });
  if (!regular) return false;
  in.jump_to(shares.back().at, first_line + long(n));
  return true;
}

}  // namespace bodyfit::io_detail
