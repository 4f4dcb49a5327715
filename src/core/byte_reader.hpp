#pragma once
// Bounds-checked reading of little-endian binary formats held in memory. Readers report problems
// as FormatError without the file name; the public entry point adds it (one "path: problem").
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace iesrgs {

class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteReader {
 public:
  explicit ByteReader(std::string_view bytes, size_t position = 0)
      : bytes_(bytes), position_(position) {
    if (position > bytes.size()) throw FormatError("offset past the end of the data");
  }

  std::string_view take(size_t count) {
    if (count > remaining()) throw FormatError("truncated data");
    const std::string_view out = bytes_.substr(position_, count);
    position_ += count;
    return out;
  }

  // The bytes up to the next '\n', which is consumed too.
  std::string_view take_line() {
    const size_t end = bytes_.find('\n', position_);
    if (end == std::string_view::npos) throw FormatError("truncated data");
    const std::string_view line = take(end - position_);
    take(1);
    return line;
  }

  // An integer stored little-endian (the host order on every supported platform).
  template <typename T>
  T little() {
    static_assert(std::is_integral_v<T>);
    T value;
    std::memcpy(&value, take(sizeof(T)).data(), sizeof(T));
    return value;
  }

  size_t position() const { return position_; }
  size_t remaining() const { return bytes_.size() - position_; }

 private:
  std::string_view bytes_;
  size_t position_;
};

}  // namespace iesrgs
