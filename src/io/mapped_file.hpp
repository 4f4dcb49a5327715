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

  // Copies up to `size` bytes from `offset` into `out` (fewer at the end of the file; returns how
  // many), then drops the pages it read whole from this process's resident memory: read through
  // once, a large file costs the page cache, not the process's memory. Touched again, pages are
  // read again.
  size_t read_through(size_t offset, void* out, size_t size) const;

  // Drops the pages lying whole within the range from this process's resident memory.
  void drop_pages(size_t offset, size_t size) const;

 private:
  const char* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace iesrgs
