#include "io/npy.hpp"

#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

void write_npy(const fs::path& path, const std::vector<float>& data,
               const std::vector<size_t>& shape) {
  size_t count = 1;
  std::string dims;
  for (size_t d : shape) {
    count *= d;
    dims += std::to_string(d) + ",";
  }
  if (count != data.size()) fail_file(path, "array size does not match its shape");
  if (shape.size() > 1) dims.pop_back();  // "(3,)" for 1-D, "(2, 3)" style otherwise
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + dims + "), }";
  // Magic (6) + version (2) + length (2) + header + '\n', padded to a multiple of 64.
  const size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header += '\n';
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes.push_back(char(header.size() & 255));
  bytes.push_back(char(header.size() >> 8));
  bytes += header;
  bytes.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
  write_file_atomically(path, bytes);
}

NpyArray read_npy(const fs::path& path) {
  const std::string bytes = read_file(path);
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0)
    fail_file(path, "not a .npy file (bad magic)");
  const int major = static_cast<unsigned char>(bytes[6]);
  size_t header_len = 0, offset = 0;
  if (major == 1) {
    header_len = uint8_t(bytes[8]) | (size_t(uint8_t(bytes[9])) << 8);
    offset = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) fail_file(path, "truncated .npy header");
    header_len = 0;
    for (int i = 0; i < 4; ++i) header_len |= size_t(uint8_t(bytes[8 + i])) << (8 * i);
    offset = 12;
  } else {
    fail_file(path, "unsupported .npy version " + std::to_string(major));
  }
  if (offset + header_len > bytes.size()) fail_file(path, "truncated .npy header");
  const std::string header = bytes.substr(offset, header_len);
  if (header.find("'<f4'") == std::string::npos)
    fail_file(path, "only little-endian float32 ('<f4') arrays are supported");
  if (header.find("'fortran_order': False") == std::string::npos)
    fail_file(path, "Fortran-order arrays are not supported");
  const size_t key = header.find("'shape':");
  const size_t open = header.find('(', key);
  const size_t close = header.find(')', open);
  if (key == std::string::npos || open == std::string::npos || close == std::string::npos)
    fail_file(path, "malformed .npy header (no shape)");
  NpyArray array;
  size_t count = 1;
  for (size_t pos = open + 1; pos < close;) {
    if (!std::isdigit(static_cast<unsigned char>(header[pos]))) {
      ++pos;  // separators: ", "
      continue;
    }
    size_t dim = 0;
    const auto [end, error] = std::from_chars(header.data() + pos, header.data() + close, dim);
    if (error != std::errc() || (dim && count > SIZE_MAX / sizeof(float) / dim))
      fail_file(path, "malformed .npy header (bad shape)");
    array.shape.push_back(dim);
    count *= dim;
    pos = size_t(end - header.data());
  }
  const size_t data_offset = offset + header_len;
  if (bytes.size() - data_offset != count * sizeof(float))
    fail_file(path, "data size does not match the header's shape");
  array.data.resize(count);
  // An array with a zero dimension has no data, and memcpy may not be given its null pointer.
  if (count > 0) std::memcpy(array.data.data(), bytes.data() + data_offset, count * sizeof(float));
  return array;
}

}  // namespace iesrgs
