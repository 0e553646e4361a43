#pragma once
// Writes a Serialize() struct (name_value.h) as YAML, keys in the order
// Serialize visits them, so that a file written here reads back through
// yaml_read_archive.h with the same keys, spelled once. Numbers are the
// shortest text that reads back to the same bits (0.6, not
// 0.59999999999999998). Header-only so that pinball_core links Eigen alone;
// a target that includes it links yaml-cpp.

#include <string>
#include <type_traits>

#include <yaml-cpp/yaml.h>

#include "pinball/core/format.h"
#include "pinball/core/name_value.h"

namespace pinball {

/// Emits the fields of one struct into a YAML::Emitter, inside a map the caller opened.
class YamlWriteArchive {
 public:
  /// Writes into `emitter`.
  explicit YamlWriteArchive(YAML::Emitter& emitter) : e_(emitter) {}

  /// One field (called by Serialize); an empty std::optional writes no key.
  template <class T>
  void Visit(const NameValue<T>& field) {
    if constexpr (archive_detail::kIsOptional<T>) {
      if (!*field.value) return;
    }
    e_ << YAML::Key << field.name << YAML::Value;
    emit(e_, *field.value);
  }

  /// Any value the archives know: scalars, text, enums, lists, optionals and Serialize() structs.
  template <class T>
  static void emit(YAML::Emitter& e, const T& value) {
    if constexpr (std::is_same_v<T, bool>) {
      e << value;
    } else if constexpr (std::is_integral_v<T>) {
      e << std::to_string(value);  // as text: yaml-cpp writes an int8_t as a character
    } else if constexpr (std::is_floating_point_v<T>) {
      e << format_exact(value);
    } else if constexpr (std::is_same_v<T, std::string>) {
      // Text that YAML would read as null (or nothing) is quoted: it must read back as text.
      const bool null_like = value.empty() || value == "~" || value == "null" || value == "Null" || value == "NULL";
      if (null_like) e << YAML::DoubleQuoted;
      e << value;
    } else if constexpr (std::is_enum_v<T>) {
      e << EnumText<T>::name(value);
    } else if constexpr (archive_detail::kIsOptional<T>) {
      if (value) {
        emit(e, *value);
      } else {
        e << YAML::Null;
      }
    } else if constexpr (archive_detail::kIsVector<T> || archive_detail::FixedList<T>) {
      // Numbers on one line ([0.5, 0.25]); text and structs one per line.
      using Item = std::remove_cvref_t<decltype(value[0])>;
      if constexpr (std::is_arithmetic_v<Item>) e << YAML::Flow;
      e << YAML::BeginSeq;
      for (std::size_t i = 0; i < static_cast<std::size_t>(value.size()); ++i) emit(e, value[i]);
      e << YAML::EndSeq;
    } else {
      e << YAML::BeginMap;
      YamlWriteArchive archive(e);
      // Serialize() is one function for reading and writing, so it is not const; writing changes nothing.
      const_cast<T&>(value).Serialize(&archive);
      e << YAML::EndMap;
    }
  }

 private:
  YAML::Emitter& e_;
};

/// `value` as a YAML document (a map for a Serialize() struct), ending in a newline.
template <class T>
std::string to_yaml_text(const T& value) {
  YAML::Emitter e;
  YamlWriteArchive::emit(e, value);
  return std::string(e.c_str()) + "\n";
}

}  // namespace pinball
