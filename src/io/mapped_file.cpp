#include "io/mapped_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/error.hpp"

namespace iesrgs {

MappedFile::MappedFile(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    fail_file(path, std::string("cannot open for reading (") + std::strerror(errno) + ")");
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error = errno;
    ::close(fd);
    fail_file(path, std::string("cannot read its size (") + std::strerror(error) + ")");
  }
  if (!S_ISREG(info.st_mode)) {
    ::close(fd);
    fail_file(path, "not a regular file");
  }
  size_ = static_cast<size_t>(info.st_size);
  if (size_ > 0) {  // mmap refuses an empty range; an empty view stands for the empty file
    void* data = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    const int error = errno;
    ::close(fd);  // the mapping keeps the file open
    if (data == MAP_FAILED)
      fail_file(path, std::string("cannot map (") + std::strerror(error) + ")");
    data_ = static_cast<const char*>(data);
  } else {
    ::close(fd);
  }
}

size_t MappedFile::read_through(size_t offset, void* out, size_t size) const {
  offset = std::min(offset, size_);
  size = std::min(size, size_ - offset);
  if (size > 0) std::memcpy(out, data_ + offset, size);
  drop_pages(offset, size);
  return size;
}

void MappedFile::drop_pages(size_t offset, size_t size) const {
  offset = std::min(offset, size_);  // never beyond the mapping, into a neighbouring one
  size = std::min(size, size_ - offset);
  static const size_t page = size_t(::sysconf(_SC_PAGESIZE));
  const size_t first = (offset + page - 1) / page * page, end = (offset + size) / page * page;
  // Advice only: pages it leaves in place cost memory, not correctness.
  if (end > first) ::madvise(const_cast<char*>(data_) + first, end - first, MADV_DONTNEED);
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(const_cast<char*>(data_), size_);
}

}  // namespace iesrgs
