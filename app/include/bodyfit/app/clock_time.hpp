#pragma once
// Clock times of a run: the ISO 8601 date-time of t = 0 ([time] start), so outputs can say when
// (a perimeter's date-time, a raster's metadata) and inputs can be given at a date-time.
#include <optional>
#include <string>
#include <string_view>

namespace bodyfit {

/// Seconds since 1970-01-01T00:00:00Z of an ISO 8601 date-time with its zone:
/// "2026-07-14T13:00:00Z", "2026-07-14T15:00:00+02:00", "2026-07-14T13:00Z", fractional seconds
/// ("…:00.5Z"), a space for the "T". nullopt when the text is not one, or has no zone (a local
/// time is ambiguous: add "Z" for UTC or the offset).
std::optional<double> parse_iso8601(std::string_view text);

/// "2026-07-14T13:00:00Z": the UTC date-time `seconds` after the epoch, to the second, or to the
/// millisecond when it is not a whole second.
std::string format_iso8601(double seconds);

}  // namespace bodyfit
