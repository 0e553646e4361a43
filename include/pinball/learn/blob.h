#pragma once
// The bytes of one task's result (a ball's outcome, a demonstration ball), so
// that results can cross between processes (MPI) and be kept in a checkpoint.
// Values go in field by field as their own bytes: the reader on the same
// build reads them back exactly (a checkpoint is for resuming on the machine
// or cluster that wrote it, not an exchange format). Only types without
// padding go in whole: a struct's padding holds whatever the memory held,
// and the same run wrote different checkpoint bytes.

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace pinball::learn {

/// One task's result as bytes.
using Blob = std::vector<std::uint8_t>;

/// A value whose every byte is its value: floating point (no padding, though
/// two NaNs may differ) or what has a unique object representation.
template <class T>
inline constexpr bool kWholeValue = std::is_floating_point_v<T> || std::has_unique_object_representations_v<T>;

/// Appends values to a blob.
class BlobWriter {
 public:
  /// Appends a value with no padding bytes (a number, a bool, an array of them).
  template <class T>
  BlobWriter& put(const T& value) {
    static_assert(kWholeValue<T>, "a struct's padding would be written: put its fields one by one");
    append(&value, sizeof(T));
    return *this;
  }
  /// Appends a vector of values with no padding bytes, its length first.
  template <class T>
  BlobWriter& put_vector(const std::vector<T>& values) {
    static_assert(kWholeValue<T>, "a struct's padding would be written: put its fields one by one");
    put<std::uint64_t>(values.size());
    append(values.data(), values.size() * sizeof(T));
    return *this;
  }
  /// The bytes written.
  Blob take() { return std::move(bytes_); }

 private:
  void append(const void* p, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, p, n);
  }
  Blob bytes_;
};

/// Reads values back in the order they were written; throws
/// std::runtime_error on a blob too short for what is asked.
class BlobReader {
 public:
  explicit BlobReader(const Blob& blob) : blob_(blob) {}
  /// The next trivially copyable value.
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T));
    T value;
    std::memcpy(&value, blob_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  /// The next vector of trivially copyable values.
  template <class T>
  std::vector<T> get_vector() {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto n = get<std::uint64_t>();
    if (n > (blob_.size() - at_) / sizeof(T)) throw std::runtime_error("blob: a vector longer than the bytes left");
    std::vector<T> values(static_cast<std::size_t>(n));
    // An empty vector's data() may be null, and memcpy from or to null is
    // undefined even for no bytes (UBSan's nonnull-attribute check).
    if (values.empty()) return values;
    std::memcpy(values.data(), blob_.data() + at_, values.size() * sizeof(T));
    at_ += values.size() * sizeof(T);
    return values;
  }
  /// Bytes read so far.
  std::size_t position() const { return at_; }
  /// True when every byte was read.
  bool at_end() const { return at_ == blob_.size(); }
  /// Throws unless every byte was read.
  void expect_end() const {
    if (at_ != blob_.size()) throw std::runtime_error("blob: bytes left over after the last field");
  }

 private:
  void need(std::size_t n) const {
    if (blob_.size() - at_ < n) throw std::runtime_error("blob: shorter than its fields");
  }
  const Blob& blob_;
  std::size_t at_ = 0;
};

}  // namespace pinball::learn
