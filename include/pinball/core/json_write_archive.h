#pragma once
// Writes a Serialize() struct (name_value.h) as a JSON object, one key per
// visited field, the same keys the read archives read. Header-only so that
// pinball_core links Eigen alone; a target that includes it links
// nlohmann_json.

#include <string>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "pinball/core/name_value.h"

namespace pinball {

/// Collects the fields of one struct into a JSON object.
class JsonWriteArchive {
 public:
  /// One field (called by Serialize); an empty std::optional writes no key.
  template <class T>
  void Visit(const NameValue<T>& field) {
    if constexpr (archive_detail::kIsOptional<T>) {
      if (!*field.value) return;
    }
    object_[field.name] = to_json(*field.value);
  }

  /// What was written.
  const nlohmann::json& object() const { return object_; }

  /// Any value the archives know: scalars, text, enums, lists, optionals and Serialize() structs.
  template <class T>
  static nlohmann::json to_json(const T& value) {
    if constexpr (std::is_arithmetic_v<T> || std::is_same_v<T, std::string>) {
      return value;
    } else if constexpr (std::is_enum_v<T>) {
      return EnumText<T>::name(value);
    } else if constexpr (archive_detail::kIsOptional<T>) {
      return value ? to_json(*value) : nlohmann::json();
    } else if constexpr (archive_detail::kIsVector<T> || archive_detail::FixedList<T>) {
      nlohmann::json list = nlohmann::json::array();
      for (std::size_t i = 0; i < static_cast<std::size_t>(value.size()); ++i) list.push_back(to_json(value[i]));
      return list;
    } else {
      JsonWriteArchive archive;
      // Serialize() is one function for reading and writing, so it is not const; writing changes nothing.
      const_cast<T&>(value).Serialize(&archive);
      return archive.object_;
    }
  }

 private:
  nlohmann::json object_ = nlohmann::json::object();
};

/// `value` as a JSON object (or, for a plain value, its JSON value).
template <class T>
nlohmann::json to_json_value(const T& value) {
  return JsonWriteArchive::to_json(value);
}

}  // namespace pinball
