// ISO 8601 date-times of [time] start and of the outputs.
#include <bodyfit/app/clock_time.hpp>

#include <doctest/doctest.h>

using namespace bodyfit;

TEST_CASE("parse_iso8601: exact seconds since the epoch, zones, fractions, refusals") {
  CHECK(parse_iso8601("1970-01-01T00:00:00Z") == 0.0);
  CHECK(parse_iso8601("2000-03-01T00:00:00Z") == 951868800.0);  // after a leap day of a century leap year
  CHECK(parse_iso8601("2026-07-14T13:00:00Z") == 1784034000.0);
  CHECK(parse_iso8601("2026-07-14T15:00:00+02:00") == 1784034000.0);
  CHECK(parse_iso8601("2026-07-14T08:30:00-0430") == 1784034000.0);
  CHECK(parse_iso8601("2026-07-14 13:00Z") == 1784034000.0);
  CHECK(parse_iso8601("2026-07-14T13:00:00.25Z") == 1784034000.25);
  CHECK(parse_iso8601("1969-12-31T23:59:59Z") == -1.0);
  CHECK_FALSE(parse_iso8601("2026-07-14T13:00:00"));   // no zone: ambiguous
  CHECK_FALSE(parse_iso8601("2026-02-29T00:00:00Z"));  // not a leap year
  CHECK_FALSE(parse_iso8601("2026-13-01T00:00:00Z"));
  CHECK_FALSE(parse_iso8601("2026-07-14T24:00:00Z"));
  CHECK_FALSE(parse_iso8601("2026-07-14T13:00:00Zjunk"));
  CHECK_FALSE(parse_iso8601("14/07/2026 13:00"));
  CHECK_FALSE(parse_iso8601(""));
}

TEST_CASE("format_iso8601: UTC to the second, milliseconds when needed, round trip") {
  CHECK(format_iso8601(0) == "1970-01-01T00:00:00Z");
  CHECK(format_iso8601(1784034000.0) == "2026-07-14T13:00:00Z");
  CHECK(format_iso8601(1784034000.0 + 86400 * 200 + 61.5) == "2027-01-30T13:01:01.500Z");
  CHECK(format_iso8601(-1) == "1969-12-31T23:59:59Z");
  CHECK(format_iso8601(951782400.0) == "2000-02-29T00:00:00Z");
  for (double t : {0.0, 1784034000.0, 951782400.0, 4102444799.0}) CHECK(parse_iso8601(format_iso8601(t)) == t);
}
