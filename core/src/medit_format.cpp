// The Medit / GMF format's shared helpers (medit_format.hpp).
#include "medit_format.hpp"

namespace bodyfit::io_detail {

/// Read the version header of a binary file and set the byte order.
BinaryFormat read_binary_header(BinaryScanner& in) {
  auto code = in.get<std::int32_t>("the code word 1");
  if (code != 1) {
    if (code == 0x01000000) {
      in.set_swap(true);
    } else {
      throw in.error(0, fmt::format("bad code word {} (expected 1 in either byte order): not a GMF binary file", code));
    }
  }
  BinaryFormat format;
  format.version = in.get<std::int32_t>("the version");
  if (format.version < 1 || format.version > 4)
    throw in.error(4, fmt::format("unsupported version {} (expected 1 to 4)", format.version));
  return format;
}

std::int64_t read_count(BinaryScanner& in, const BinaryFormat& format, const char* section) {
  const std::size_t at = in.pos();
  std::int64_t n = format.int64_integers() ? in.get<std::int64_t>("a record count")
                                           : std::int64_t(in.get<std::int32_t>("a record count"));
  if (n < 0) throw in.error(at, fmt::format("negative record count {} for {}", n, section));
  return n;
}

void check_dimension(int dimension, const std::function<InputError(const std::string&)>& error) {
  if (dimension != 2 && dimension != 3) throw error(fmt::format("unsupported Dimension {} (expected 2 or 3)", dimension));
}

int read_binary_dimension(BinaryScanner& in, std::size_t start) {
  const int dimension = in.get<std::int32_t>("the dimension");
  check_dimension(dimension, [&](const std::string& w) { return in.error(start, w); });
  return dimension;
}

void require_version(bool versioned, const std::filesystem::path& file, const char* what) {
  if (!versioned) throw file_error(file, 1, fmt::format("missing MeshVersionFormatted: not a Medit {} file", what));
}

bool plausible_count(std::int64_t count, std::size_t remaining, std::size_t min_bytes) {
  return count >= 0 && std::uint64_t(count) <= remaining / min_bytes + 1;
}

BinaryFormat binary_format_for(std::uint64_t estimated_bytes) {
  BinaryFormat format;
  format.version = estimated_bytes < (1ull << 31) - 1024 ? 2 : 3;  // 64-bit positions past 2 GB
  return format;
}

}  // namespace bodyfit::io_detail
