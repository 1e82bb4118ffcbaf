#include <bodyfit/app/clock_time.hpp>

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstdint>

namespace bodyfit {
namespace {

// Days from 1970-01-01 to a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = unsigned(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + std::int64_t(doe) - 719468;
}

struct Civil {
  std::int64_t year;
  unsigned month, day;
};
Civil civil_from_days(std::int64_t z) {
  z += 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const auto doe = unsigned(z - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  const unsigned d = doy - (153 * mp + 2) / 5 + 1;
  const unsigned m = mp < 10 ? mp + 3 : mp - 9;
  return {std::int64_t(yoe) + era * 400 + (m <= 2), m, d};
}

bool leap(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

// A reader of fixed-width digit fields and separators.
struct Scanner {
  std::string_view s;
  std::size_t i = 0;
  bool digits(int n, int& out) {
    out = 0;
    for (int k = 0; k < n; ++k, ++i) {
      if (i >= s.size() || !std::isdigit(static_cast<unsigned char>(s[i]))) return false;
      out = out * 10 + (s[i] - '0');
    }
    return true;
  }
  bool take(char c) {
    if (i < s.size() && s[i] == c) return ++i, true;
    return false;
  }
  bool done() const { return i == s.size(); }
};

}  // namespace

std::optional<double> parse_iso8601(std::string_view text) {
  Scanner in{text};
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (!in.digits(4, year) || !in.take('-') || !in.digits(2, month) || !in.take('-') || !in.digits(2, day))
    return std::nullopt;
  if (!in.take('T') && !in.take(' ')) return std::nullopt;
  if (!in.digits(2, hour) || !in.take(':') || !in.digits(2, minute)) return std::nullopt;
  double fraction = 0;
  if (in.take(':')) {
    if (!in.digits(2, second)) return std::nullopt;
    if (in.take('.') || in.take(',')) {
      double scale = 0.1;
      const std::size_t start = in.i;
      while (in.i < text.size() && std::isdigit(static_cast<unsigned char>(text[in.i])))
        fraction += scale * (text[in.i++] - '0'), scale /= 10;
      if (in.i == start) return std::nullopt;
    }
  }
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (month < 1 || month > 12 || day < 1 || day > kDays[month - 1] + (month == 2 && leap(year)) || hour > 23 ||
      minute > 59 || second > 59)
    return std::nullopt;
  int offset_minutes = 0;
  if (in.take('Z')) {
  } else if (text.size() > in.i && (text[in.i] == '+' || text[in.i] == '-')) {
    const int sign = text[in.i++] == '+' ? 1 : -1;
    int oh = 0, om = 0;
    if (!in.digits(2, oh)) return std::nullopt;
    in.take(':');
    if (!in.done() && !in.digits(2, om)) return std::nullopt;
    if (oh > 23 || om > 59) return std::nullopt;
    offset_minutes = sign * (oh * 60 + om);
  } else {
    return std::nullopt;  // no zone
  }
  if (!in.done()) return std::nullopt;
  const std::int64_t days = days_from_civil(year, unsigned(month), unsigned(day));
  return double(days * 86400 + hour * 3600 + minute * 60 + second - offset_minutes * 60) + fraction;
}

std::string format_iso8601(double seconds) {
  const double whole = std::floor(seconds);
  auto millis = std::int64_t(std::llround((seconds - whole) * 1000));
  auto total = std::int64_t(whole);
  if (millis == 1000) ++total, millis = 0;
  std::int64_t days = total / 86400, rest = total % 86400;
  if (rest < 0) rest += 86400, --days;
  const Civil date = civil_from_days(days);
  std::string text = fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}", date.year, date.month, date.day, rest / 3600,
                                 rest / 60 % 60, rest % 60);
  if (millis) text += fmt::format(".{:03}", millis);
  return text + "Z";
}

}  // namespace bodyfit
