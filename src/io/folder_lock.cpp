#include "io/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "core/error.hpp"

namespace iesrgs {

FolderLock::FolderLock(const std::filesystem::path& folder) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) fail_file(folder, "cannot create the output folder (" + ec.message() + ")");
  // A directory can be locked itself: no lock file is left among the outputs.
  fd_ = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    fail_file(folder, std::string("cannot open the output folder (") + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) return;
  const int error = errno;
  if (error != EWOULDBLOCK) return;  // no locks on this file system
  ::close(fd_);
  fd_ = -1;
  fail_file(folder,
            "in use by another iesrgs process; wait for it to end (or stop it) before writing "
            "to this folder again");
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace iesrgs
