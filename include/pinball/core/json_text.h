#pragma once
// The one way a JSON value becomes text (a report, a file). nlohmann's dump()
// throws on a string that is not UTF-8, and a file name may be Latin-1 (a
// folder made by another system): the report of a finished run would be lost
// to its path. Bad bytes are written as U+FFFD instead.

#include <string>

#include <nlohmann/json.hpp>

namespace pinball {

/// `j` as text, indented by `indent` spaces per level (-1: one line).
inline std::string json_text(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace pinball
