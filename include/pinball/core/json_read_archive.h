#pragma once
// ReadArchive over nlohmann::json: reads a JSON document into a Serialize()
// struct. Header-only so that pinball_core links Eigen alone; a target that
// includes it links nlohmann_json.

#include <optional>
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

}  // namespace pinball
