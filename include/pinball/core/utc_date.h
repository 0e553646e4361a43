#pragma once
// The one way files and score rows are dated: ISO 8601 in UTC, to the second
// (2026-12-02T13:45:21Z), so that a date sorts as text and means the same
// wherever it was written.

#include <string>

namespace pinball {

/// The current time as ISO 8601 UTC, to the second.
std::string utc_now_iso8601();

}  // namespace pinball
