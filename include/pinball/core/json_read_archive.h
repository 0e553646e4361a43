#pragma once
// ReadArchive over nlohmann::json: reads a JSON document into a Serialize()
// struct. Header-only so that pinball_core links Eigen alone; a target that
// includes it links nlohmann_json.

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/core/read_archive.h"

namespace pinball {

/// nlohmann::json as a ReadArchive document. Values are typed: "3" is text,
/// not an integer.
struct JsonDoc {
  using Node = const nlohmann::json*;
  static bool is_null(Node n) { return !n || n->is_null(); }
  static bool is_map(Node n) { return n->is_object(); }
  static bool is_list(Node n) { return n->is_array(); }
  static std::optional<Node> find(Node map, const char* key) {
    if (!map->is_object()) return std::nullopt;
    const auto it = map->find(key);
    return it == map->end() ? std::nullopt : std::optional<Node>(&*it);
  }
  static std::vector<std::string> keys(Node map) {
    std::vector<std::string> out;
    for (const auto& kv : map->items()) out.push_back(kv.key());
    return out;
  }
  static std::size_t size(Node list) { return list->size(); }
  static Node at(Node list, std::size_t i) { return &(*list)[i]; }
  static bool get_bool(Node n, bool* out) {
    if (!n->is_boolean()) return false;
    *out = n->get<bool>();
    return true;
  }
  static bool get_double(Node n, double* out) {
    if (!n->is_number()) return false;
    *out = n->get<double>();
    return true;
  }
  static bool get_string(Node n, std::string* out) {
    if (!n->is_string()) return false;
    *out = n->get<std::string>();
    return true;
  }
  static std::string describe(Node n) {
    if (is_null(n)) return "null";
    if (n->is_object()) return "an object";
    if (n->is_array()) return "a list of " + std::to_string(n->size());
    if (n->is_string()) return "text " + quote_value(n->get<std::string>());
    return n->dump();  // a number or a boolean, as written
  }
  static int line(Node) { return 0; }  // nlohmann keeps no positions
  static IntegerParse get_int(Node n, std::int64_t* out) {
    if (n->is_number_unsigned()) {
      const auto u = n->get<std::uint64_t>();
      if (!std::in_range<std::int64_t>(u)) return IntegerParse::kOutOfRange;
      *out = static_cast<std::int64_t>(u);
      return IntegerParse::kOk;
    }
    if (!n->is_number_integer()) return IntegerParse::kNotInteger;
    *out = n->get<std::int64_t>();
    return IntegerParse::kOk;
  }
  static IntegerParse get_uint(Node n, std::uint64_t* out) {
    if (!n->is_number_unsigned()) return IntegerParse::kNotInteger;
    *out = n->get<std::uint64_t>();
    return IntegerParse::kOk;
  }
};

/// Reads JSON into Serialize() structs.
using JsonReadArchive = ReadArchive<JsonDoc>;

namespace json_detail {

// One open object or array while parsing, for the path of a repeated key.
struct OpenValue {
  bool object = false;
  std::set<std::string> keys;  // objects: the keys so far
  std::string key;             // objects: the latest key
  std::size_t index = 0;       // arrays: elements so far
};

// The path ("minicontrollers[2].a") of the value being read inside the
// innermost open value, built only when an error needs it: a path kept per
// level would cost the square of the depth for deeply nested text.
inline std::string path_of(const std::vector<OpenValue>& open) {
  std::string path;
  for (std::size_t i = 0; i + 1 < open.size(); ++i) {
    path = open[i].object ? join_key(path, open[i].key) : path + "[" + std::to_string(open[i].index) + "]";
  }
  return path;
}

}  // namespace json_detail

/// Parses JSON text. Throws KeyError: key "(file)" for text that is not JSON
/// (nlohmann's message says where: "at line 3, column 7") or a number too
/// large for a double; the key's path for a key given twice, which nlohmann
/// would otherwise resolve silently by keeping the last.
inline nlohmann::json parse_json(const std::string& text, const std::string& file) {
  using nlohmann::json;
  std::vector<json_detail::OpenValue> open;
  const auto element_done = [&] {
    if (!open.empty() && !open.back().object) ++open.back().index;
  };
  const json::parser_callback_t watch = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        open.push_back({event == json::parse_event_t::object_start, {}, {}, 0});
        break;
      case json::parse_event_t::key:
        open.back().key = parsed.get<std::string>();
        if (!open.back().keys.insert(open.back().key).second) {
          throw KeyError(file, join_key(json_detail::path_of(open), open.back().key), "duplicate key");
        }
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        open.pop_back();
        element_done();
        break;
      case json::parse_event_t::value:
        element_done();
        break;
    }
    return true;
  };
  try {
    return json::parse(text, watch);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for 1e400
    // Without nlohmann's "[json.exception.parse_error.101] " tag: a reader wants where and what.
    std::string what = e.what();
    const std::size_t tag_end = what.find("] ");
    if (what.starts_with("[json.exception.") && tag_end != std::string::npos) what.erase(0, tag_end + 2);
    throw KeyError(file, "(file)", "not valid JSON: " + what);
  }
}

}  // namespace pinball
