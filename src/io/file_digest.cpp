#include "io/file_digest.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

#include "core/error.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

constexpr uint64_t kFnvOffset = 14695981039346656037ull;
constexpr uint64_t kFnvPrime = 1099511628211ull;

uint64_t fnv_mix(uint64_t hash, uint64_t word) {
  return (hash ^ word) * kFnvPrime;
}

uint64_t mix_bytes(uint64_t hash, const char* bytes, size_t size) {
  size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    uint64_t word;
    std::memcpy(&word, bytes + i, 8);
    hash = fnv_mix(hash, word);
  }
  for (; i < size; ++i) hash = fnv_mix(hash, uint8_t(bytes[i]));
  return hash;
}

}  // namespace

std::string file_digest(const fs::path& path) {
  std::error_code ec;
  if (path.empty() || !fs::is_regular_file(path, ec)) return "-";
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_file(path, "cannot be opened for reading");
  uint64_t hash = fnv_mix(kFnvOffset, fs::file_size(path, ec));
  // Whole words per chunk, so that the result does not depend on where chunks end.
  std::vector<char> chunk(size_t(1) << 20);
  while (in) {
    in.read(chunk.data(), std::streamsize(chunk.size()));
    hash = mix_bytes(hash, chunk.data(), size_t(in.gcount()));
  }
  if (in.bad()) fail_file(path, "read error");
  return fmt::format("{:016x}", hash);
}

std::string bytes_digest(std::string_view bytes) {
  return fmt::format("{:016x}",
                     mix_bytes(fnv_mix(kFnvOffset, bytes.size()), bytes.data(), bytes.size()));
}

std::string directory_digest(const fs::path& dir) {
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) return "-";
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());  // listing order is the file system's
  std::string key;
  for (const fs::path& file : files)
    key += file.filename().string() + " " + file_digest(file) + "\n";
  return bytes_digest(key);
}

}  // namespace iesrgs
