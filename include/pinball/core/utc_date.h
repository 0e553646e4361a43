#pragma once
// The one way files and score rows are dated: ISO 8601 in UTC, to the second
// (2026-12-02T13:45:21Z), so that a date sorts as text and means the same
// wherever it was written.

#include <string>
#include <string_view>

namespace pinball {

/// The current time as ISO 8601 UTC, to the second.
std::string utc_now_iso8601();

/// True when `text` is a date as utc_now_iso8601 writes it: YYYY-MM-DDTHH:MM:SSZ,
/// a real calendar day, hours 0..23, minutes 0..59, seconds 0..60 (a leap second).
bool is_utc_iso8601(std::string_view text);

}  // namespace pinball
