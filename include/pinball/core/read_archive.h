#pragma once
// The one checked key reader: fills any struct with a Serialize() (see
// name_value.h) from a YAML or JSON document, naming `file:key.path` in every
// error and refusing wrong types (saying which type was expected, what the
// file holds and, where the document knows it, the line: "expected a number
// (double), got 'fast' (line 3)"), integers that do not fit the field,
// non-finite numbers, keys given twice and, unless told otherwise, unknown
// keys. `Doc` adapts one document type (yaml_read_archive.h,
// json_read_archive.h); this file knows no parser.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>

#include "pinball/core/name_value.h"

namespace pinball {

/// What a reader does with keys the file has and the struct lacks, and the reverse.
struct ReadOptions {
  /// A key the struct lacks is an error: a misspelt key must not silently keep a default.
  bool refuse_unknown_keys = true;
  /// A key the file lacks is an error; false: the field keeps its default.
  /// A std::optional field may always be absent.
  bool require_every_key = false;
};

/// How a document's value parsed as an integer.
enum class IntegerParse { kOk, kNotInteger, kOutOfRange };

/// Parses a whole decimal integer (an optional leading '+').
template <class I>
IntegerParse parse_decimal_integer(const std::string& text, I* out) {
  const char* first = text.data();
  const char* last = first + text.size();
  if (first != last && *first == '+') ++first;
  const auto [end, ec] = std::from_chars(first, last, *out);
  if (ec == std::errc::result_out_of_range) return IntegerParse::kOutOfRange;
  return ec == std::errc() && end == last ? IntegerParse::kOk : IntegerParse::kNotInteger;
}

/// A value from a file, quoted for a message: cut at 40 characters, bytes
/// outside printable ASCII shown as '?' (a binary file must not garble the terminal).
inline std::string quote_value(const std::string& text) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    out += c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?';
  }
  return out + (text.size() > kMax ? "...'" : "'");
}

/// The name of an arithmetic field's type in messages: "double", "int32", "uint8".
template <class T>
std::string number_type_name() {
  if constexpr (std::is_floating_point_v<T>) {
    return sizeof(T) == sizeof(float) ? "float" : "double";
  } else {
    return std::string(std::is_signed_v<T> ? "int" : "uint") + std::to_string(8 * sizeof(T));
  }
}

/// Reads documents of one kind into Serialize() structs. `Doc` gives `Node`
/// and is_null, is_map, is_list, find, keys, size, at, get_bool, get_int,
/// get_uint, get_double, get_string, describe (what a value is, for messages:
/// "'fast'", "a list") and line (1-based; 0 where the document has none).
template <class Doc>
class ReadArchive {
 public:
  using Node = typename Doc::Node;

  /// `file` names the document in every error.
  explicit ReadArchive(std::string file, ReadOptions options = {}) : file_(std::move(file)), options_(options) {}

  /// Reads `node` into `out`; `key` is its path in the file ("" at the top).
  /// Throws KeyError.
  template <class T>
  void read(const Node& node, const std::string& key, T* out) {
    read_value(node, key, out);
  }

  /// One field of the struct being read (called by Serialize).
  template <class T>
  void Visit(const NameValue<T>& field) {
    frame_->used.insert(field.name);
    const std::string key = join_key(frame_->path, field.name);
    const std::optional<Node> child = Doc::find(frame_->node, field.name);
    if (!child) {
      if constexpr (archive_detail::kIsOptional<T>) {
        field.value->reset();
      } else if (options_.require_every_key) {
        fail(key, "missing");
      }
      return;
    }
    read_value(*child, key, field.value);
  }

  /// Throws KeyError(file, key, message): the one way a reader reports.
  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw KeyError(file_, key, message);
  }

  const std::string& file() const { return file_; }  ///< the document's name

 private:
  // The mapping a Serialize() is walking and the keys it has used.
  struct Frame {
    Node node;
    std::string path;
    std::set<std::string> used;
  };

  template <class T>
  void read_value(const Node& n, const std::string& key, T* out) {
    using archive_detail::FixedList;
    if constexpr (std::is_same_v<T, bool>) {
      if (!Doc::get_bool(n, out)) fail_type(n, key, "expected true or false");
    } else if constexpr (std::is_integral_v<T>) {
      read_integer(n, key, out);
    } else if constexpr (std::is_floating_point_v<T>) {
      double v = 0.0;
      if (!Doc::get_double(n, &v)) fail_type(n, key, "expected a number (" + number_type_name<T>() + ")");
      if (!std::isfinite(v)) fail_type(n, key, "expected a finite number (" + number_type_name<T>() + ")");
      *out = static_cast<T>(v);
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!Doc::get_string(n, out)) fail_type(n, key, "expected text");
    } else if constexpr (std::is_enum_v<T>) {
      std::string text;
      read_value(n, key, &text);
      try {
        *out = EnumText<T>::parse(text);
      } catch (const std::invalid_argument& e) {
        fail(key, e.what());
      }
    } else if constexpr (archive_detail::kIsOptional<T>) {
      read_value(n, key, &out->emplace());
    } else if constexpr (archive_detail::kIsVector<T>) {
      if (!Doc::is_list(n)) fail_type(n, key, "expected a list");
      out->assign(Doc::size(n), typename T::value_type{});
      for (std::size_t i = 0; i < out->size(); ++i) read_value(Doc::at(n, i), index_key(key, i), &(*out)[i]);
    } else if constexpr (FixedList<T>) {
      constexpr std::size_t size = archive_detail::fixed_size<T>();
      if (!Doc::is_list(n) || Doc::size(n) != size) fail_type(n, key, "expected a list of " + std::to_string(size));
      for (std::size_t i = 0; i < size; ++i) read_value(Doc::at(n, i), index_key(key, i), &(*out)[i]);
    } else {
      static_assert(requires(T& t, ReadArchive* a) { t.Serialize(a); }, "a field type the archive cannot read");
      read_struct(n, key, out);
    }
  }

  // " (line 3)" where the document knows the line, else "".
  static std::string where(const Node& n) {
    const int line = Doc::line(n);
    return line > 0 ? " (line " + std::to_string(line) + ")" : "";
  }

  // A value of the wrong type: what was expected, what the file holds, where.
  [[noreturn]] void fail_type(const Node& n, const std::string& key, const std::string& expected) const {
    fail(key, expected + ", got " + Doc::describe(n) + where(n));
  }

  // Integers go through 64 bits and must fit the field: 300 is refused for a
  // uint8_t, not wrapped to 44.
  template <class T>
  void read_integer(const Node& n, const std::string& key, T* out) {
    std::int64_t s = 0;
    std::uint64_t u = 0;
    IntegerParse r = IntegerParse::kNotInteger;
    bool fits = false;
    if constexpr (std::is_signed_v<T>) {
      r = Doc::get_int(n, &s);
      fits = r == IntegerParse::kOk && std::in_range<T>(s);
      if (fits) *out = static_cast<T>(s);
    } else {
      r = Doc::get_uint(n, &u);
      if (r == IntegerParse::kNotInteger && Doc::get_int(n, &s) == IntegerParse::kOk) r = IntegerParse::kOutOfRange;
      fits = r == IntegerParse::kOk && std::in_range<T>(u);
      if (fits) *out = static_cast<T>(u);
    }
    if (fits) return;
    if (r == IntegerParse::kNotInteger) fail_type(n, key, "expected an integer (" + number_type_name<T>() + ")");
    fail_type(n, key,
              "expected an integer in [" + std::to_string(std::numeric_limits<T>::min()) + ", " +
                  std::to_string(std::numeric_limits<T>::max()) + "]");
  }

  template <class T>
  void read_struct(const Node& n, const std::string& path, T* out) {
    if (Doc::is_null(n) && !options_.require_every_key) return;  // an empty section keeps its defaults
    if (!Doc::is_map(n)) fail_type(n, path.empty() ? "(top)" : path, "expected a mapping");
    refuse_repeated_keys(n, path);
    Frame frame{n, path, {}};
    Frame* const outer = std::exchange(frame_, &frame);
    out->Serialize(this);
    frame_ = outer;
    if (!options_.refuse_unknown_keys) return;
    for (const std::string& k : Doc::keys(n)) {
      if (!frame.used.count(k)) fail(join_key(path, k), "unknown key");
    }
  }

  // A key given twice is refused: which of the two values counts would
  // depend on the parser, and a reader of the file cannot tell.
  void refuse_repeated_keys(const Node& n, const std::string& path) const {
    std::set<std::string> seen;
    for (const std::string& k : Doc::keys(n)) {
      if (!seen.insert(k).second) fail(join_key(path, k), "duplicate key");
    }
  }

  static std::string index_key(const std::string& key, std::size_t i) {
    return key + "[" + std::to_string(i) + "]";
  }

  std::string file_;
  ReadOptions options_;
  Frame* frame_ = nullptr;
};

}  // namespace pinball
