// Text records one per line, cut into shares for the threads (text_records.hpp).
#include "text_records.hpp"

#include <algorithm>
#include <cstring>

namespace bodyfit::io_detail {

// Byte counters that the compiler keeps in vector registers (30× std::count's speed), emptied
// before they can overflow.
std::int64_t count_line_breaks(const char* from, const char* to) {
  constexpr std::size_t kLanes = 64;
  std::int64_t total = 0;
  while (from < to) {
    const std::size_t length = std::min(std::size_t(to - from), 255 * kLanes);
    std::uint8_t lanes[kLanes] = {};
    std::size_t i = 0;
    for (; i + kLanes <= length; i += kLanes)
      for (std::size_t k = 0; k < kLanes; ++k) lanes[k] += from[i + k] == '\n';
    for (std::size_t k = 0; k < kLanes; ++k) total += lanes[k];
    for (; i < length; ++i) total += from[i] == '\n';
    from += length;
  }
  return total;
}

std::vector<LineShare> share_lines(std::string_view text, std::int64_t n, int shares) {
  constexpr std::size_t kBlock = 1 << 16;  // bytes per task of the count
  const char* begin = text.data();
  // Line breaks before each block, then the block holding the n-th: where the n lines end.
  const std::size_t blocks = (text.size() + kBlock - 1) / kBlock;
  std::vector<std::int64_t> breaks(blocks + 1, 0);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    breaks[b + 1] = count_line_breaks(begin + b * kBlock, begin + std::min(text.size(), (b + 1) * kBlock));
  });
  for (std::size_t b = 0; b < blocks; ++b) breaks[b + 1] += breaks[b];
  if (breaks[blocks] < n) return {};
  const std::size_t last = std::size_t(std::lower_bound(breaks.begin(), breaks.end(), n) - breaks.begin()) - 1;
  const char* stop = begin + last * kBlock;
  for (std::int64_t seen = breaks[last]; seen < n; ++stop)
    if (*stop == '\n') ++seen;

  // A share starts after the first break at or after its first block's start; the breaks before
  // that one are those of the blocks before.
  std::vector<LineShare> starts{{begin, 0}};
  for (int t = 1; t < shares; ++t) {
    const std::size_t b = std::size_t(stop - begin) * std::size_t(t) / std::size_t(shares) / kBlock;
    if (b == 0 || b <= std::size_t(starts.back().at - begin) / kBlock) continue;
    const char* from = begin + b * kBlock;
    const auto* line_break = static_cast<const char*>(std::memchr(from, '\n', std::size_t(stop - from)));
    if (!line_break || line_break + 1 >= stop) break;
    starts.push_back({line_break + 1, breaks[std::size_t(line_break - begin) / kBlock] + 1});
  }
  starts.push_back({stop, n});
  return starts;
}

}  // namespace bodyfit::io_detail
