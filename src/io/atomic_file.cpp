#include "io/atomic_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>

#include "core/error.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kTemporaryMark = ".tmp-";

fs::path temporary_path(const fs::path& path) {
  return path.string() + std::string(kTemporaryMark) + std::to_string(::getpid());
}

// "<name>.tmp-<digits>", as temporary_path names them.
bool is_temporary(const fs::path& path) {
  const std::string name = path.filename().string();
  const size_t mark = name.rfind(kTemporaryMark);
  if (mark == std::string::npos || mark == 0) return false;
  const size_t digits = mark + kTemporaryMark.size();
  return digits < name.size() && std::all_of(name.begin() + std::ptrdiff_t(digits), name.end(),
                                             [](unsigned char c) { return std::isdigit(c); });
}

}  // namespace

void write_atomically(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  std::error_code ec;
  if (path.has_parent_path()) {
    fs::create_directories(path.parent_path(), ec);
    if (ec) fail_file(path.parent_path(), "cannot create directory: " + ec.message());
  }
  const fs::path tmp = temporary_path(path);
  try {
    write(tmp);
    fs::rename(tmp, path, ec);
    if (ec) fail_file(path, "cannot move finished file into place: " + ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void remove_stale_temporaries(const fs::path& folder) {
  std::error_code walk;
  for (fs::recursive_directory_iterator it(folder, walk), end; !walk && it != end;
       it.increment(walk)) {
    std::error_code ec;  // an entry that cannot be checked or removed is left alone
    if (it->is_regular_file(ec) && is_temporary(it->path())) fs::remove(it->path(), ec);
  }
}

void write_file_atomically(const fs::path& path, const std::string& bytes) {
  write_atomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) fail_file(path, "write failed (disk full or not writable?)");
  });
}

std::string read_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail_file(path, "file not found");
  if (fs::is_directory(path, ec)) fail_file(path, "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_file(path, "cannot open for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) fail_file(path, "read error");
  return buffer.str();
}

}  // namespace iesrgs
