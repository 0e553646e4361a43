#pragma once
// Fields spelled once (Drake's common/name_value.h): a struct lists its fields
// in `template <class Archive> void Serialize(Archive* a)`, one
// `a->Visit(PINBALL_NVP(field))` each, and every archive walks that list:
// yaml_read_archive.h and json_read_archive.h read files into it,
// json_write_archive.h writes it. The key in a file is the field's name.

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

namespace pinball {

/// One field: its key in files and where it lives.
template <class T>
struct NameValue {
  const char* name;  ///< the key
  T* value;          ///< the field
};

/// A NameValue whose key differs from the field's name (or a proxy's).
template <class T>
NameValue<T> make_name_value(const char* name, T* value) {
  return {name, value};
}

/// The field under its own name: `a->Visit(PINBALL_NVP(fps))` is key "fps".
#define PINBALL_NVP(field) ::pinball::make_name_value(#field, &(field))

/// How an enum is spelled in files. Specialise it with
/// `static std::string name(E)` and `static E parse(const std::string&)`,
/// which throws std::invalid_argument saying what it expected.
template <class E>
struct EnumText;

/// A bad key in a file, at load time: what() is "file:key: message", the
/// file and the dotted key path (`camera.fps`, `flippers[0].name`) apart too,
/// so that a module can restate it in its own error type.
class KeyError : public std::runtime_error {
 public:
  KeyError(std::string file, std::string key, std::string message)
      : std::runtime_error(file + ":" + key + ": " + message),
        file_(std::move(file)), key_(std::move(key)), message_(std::move(message)) {}

  const std::string& file() const { return file_; }        ///< the file's name as given
  const std::string& key() const { return key_; }          ///< dotted key path
  const std::string& message() const { return message_; }  ///< what is wrong

 private:
  std::string file_;
  std::string key_;
  std::string message_;
};

/// `path.key`, or `key` at the top.
inline std::string join_key(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

/// What the archives tell apart beyond scalars and structs.
namespace archive_detail {
template <class T>
inline constexpr bool kIsOptional = false;
template <class T>
inline constexpr bool kIsOptional<std::optional<T>> = true;
template <class T>
inline constexpr bool kIsVector = false;
template <class T>
inline constexpr bool kIsVector<std::vector<T>> = true;
/// std::array, or a fixed-size Eigen vector (Vec2): a list of exactly N.
template <class T>
concept FixedList = requires { std::tuple_size<T>::value; } || requires { T::SizeAtCompileTime; };
template <class T>
constexpr std::size_t fixed_size() {
  if constexpr (requires { std::tuple_size<T>::value; }) {
    return std::tuple_size_v<T>;
  } else {
    static_assert(T::SizeAtCompileTime > 0 && T::ColsAtCompileTime == 1, "only fixed-size column vectors");
    return static_cast<std::size_t>(T::SizeAtCompileTime);
  }
}
}  // namespace archive_detail

}  // namespace pinball
