#pragma once
// A file mapped read-only into memory: its pages are read on demand and belong to the page cache,
// so checking a large file needs no copy of it on the heap. The price: a read error of the disk,
// or another process truncating the file while it is mapped, ends the process (SIGBUS) where a
// read would report an error. Outputs here are replaced by renaming, never truncated.
#include <filesystem>
#include <string_view>

namespace iesrgs {

class MappedFile {
 public:
  // Throws Error naming the file when it cannot be opened or mapped.
  explicit MappedFile(const std::filesystem::path& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view bytes() const { return {data_, size_}; }

 private:
  const char* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace iesrgs
