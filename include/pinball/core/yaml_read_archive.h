#pragma once
// ReadArchive over yaml-cpp: reads a YAML document into a Serialize() struct.
// Header-only so that pinball_core links Eigen alone; a target that includes
// it links yaml-cpp.

#include <algorithm>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "pinball/core/read_archive.h"

namespace pinball {

/// yaml-cpp as a ReadArchive document. Scalars are text; numbers and
/// booleans are parsed from it. yaml-cpp keeps both entries of a repeated
/// key (and find() answers the first): keys() lists both, and ReadArchive
/// refuses the repeat.
struct YamlDoc {
  using Node = YAML::Node;
  static bool is_null(const Node& n) { return !n || n.IsNull(); }
  static bool is_map(const Node& n) { return n.IsMap(); }
  static bool is_list(const Node& n) { return n.IsSequence(); }
  static std::optional<Node> find(const Node& map, const char* key) {
    if (!map.IsMap()) return std::nullopt;
    const Node child = map[key];
    return child ? std::optional<Node>(child) : std::nullopt;
  }
  static std::vector<std::string> keys(const Node& map) {
    std::vector<std::string> out;
    for (const auto& kv : map) out.push_back(kv.first.Scalar());
    return out;
  }
  static std::size_t size(const Node& list) { return list.size(); }
  static Node at(const Node& list, std::size_t i) { return list[i]; }
  static bool get_bool(const Node& n, bool* out) { return n.IsScalar() && YAML::convert<bool>::decode(n, *out); }
  static bool get_double(const Node& n, double* out) {
    return n.IsScalar() && YAML::convert<double>::decode(n, *out);
  }
  static bool get_string(const Node& n, std::string* out) {
    if (!n.IsScalar()) return false;
    *out = n.Scalar();
    return true;
  }
  static std::string describe(const Node& n) {
    if (is_null(n)) return "nothing";
    if (n.IsMap()) return "a mapping";
    if (n.IsSequence()) return "a list of " + std::to_string(n.size());
    return quote_value(n.Scalar());
  }
  static int line(const Node& n) { return n ? n.Mark().line + 1 : 0; }
  static IntegerParse get_int(const Node& n, std::int64_t* out) {
    return n.IsScalar() ? parse_decimal_integer(n.Scalar(), out) : IntegerParse::kNotInteger;
  }
  static IntegerParse get_uint(const Node& n, std::uint64_t* out) {
    return n.IsScalar() ? parse_decimal_integer(n.Scalar(), out) : IntegerParse::kNotInteger;
  }
};

/// Reads YAML into Serialize() structs.
using YamlReadArchive = ReadArchive<YamlDoc>;

/// YAML that does not parse; key() is the line number ("file:line: message").
class YamlSyntaxError : public KeyError {
 public:
  using KeyError::KeyError;
};

namespace yaml_detail {
// yaml-cpp reads a bare word on its own line after a mapping's keys ("sim", the
// last line of a file cut short) as the key of an empty value, which a section
// takes for "all defaults"; YAML has no such line. A key without a value must
// have its ':' on the key's line.
inline void refuse_keys_without_colon(const YAML::Node& n, const std::vector<std::string_view>& lines,
                                      const std::string& file) {
  if (n.IsSequence()) {
    for (const YAML::Node& item : n) refuse_keys_without_colon(item, lines, file);
    return;
  }
  if (!n.IsMap()) return;
  for (const auto& entry : n) {
    const YAML::Node& value = entry.second;
    if (value.IsNull()) {
      const YAML::Mark at = entry.first.Mark();
      const bool known = at.line >= 0 && static_cast<std::size_t>(at.line) < lines.size();
      const std::size_t from = static_cast<std::size_t>(std::max(at.column, 0));
      if (known && lines[static_cast<std::size_t>(at.line)].find(':', from) == std::string_view::npos) {
        throw YamlSyntaxError(file, std::to_string(at.line + 1),
                              "not valid YAML: '" + entry.first.Scalar() +
                                  "' has no ':' after it (a key is 'key: value'; is the file cut short?)");
      }
    }
    refuse_keys_without_colon(value, lines, file);
  }
}
}  // namespace yaml_detail

/// Parses YAML text holding at most one document (none: a null node).
/// Throws YamlSyntaxError "file:line: not valid YAML: ...", also for a second
/// document after `---`: yaml-cpp's Load would keep the first and silently
/// drop the rest, and for a bare word where a key needs its ':'.
inline YAML::Node load_yaml(const std::string& text, const std::string& file) {
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::ParserException& e) {
    throw YamlSyntaxError(file, std::to_string(e.mark.line + 1), "not valid YAML: " + e.msg);
  }
  if (documents.size() > 1) {
    throw YamlSyntaxError(file, std::to_string(documents[1].Mark().line + 1),
                          "not valid YAML: a second YAML document (after ---): a file holds one");
  }
  if (documents.empty()) return YAML::Node();
  std::vector<std::string_view> lines;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    lines.push_back(std::string_view(text).substr(start, end - start));
    start = end + 1;
  }
  yaml_detail::refuse_keys_without_colon(documents.front(), lines, file);
  return documents.front();
}

/// A versioned file's version, read first whatever else the file holds, so
/// that a file of another version is refused as such (KeyError
/// "file:version: ..."); `kind` names the file type ("a calibration file").
namespace yaml_detail {
struct VersionKey {  // the version alone
  int version = 0;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(version));
  }
};
}  // namespace yaml_detail

inline void require_yaml_version(const YAML::Node& root, const std::string& file, int version, const char* kind) {
  ReadArchive<YamlDoc> first(file, {.refuse_unknown_keys = false, .require_every_key = true});
  if (!root.IsMap()) first.fail("version", std::string("missing (not ") + kind + ")");
  yaml_detail::VersionKey v;
  first.read(root, "", &v);
  if (v.version != version)
    first.fail("version", std::to_string(v.version) + " is not the supported version " + std::to_string(version));
}

}  // namespace pinball
