#include "io/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

// A folder inside one that another process holds (a run's stage folders, say) is that process's
// to write: a `train` or `render` there would change what the run has cached under it.
void refuse_inside_held_folder(const fs::path& folder) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(folder, ec);
  if (ec) return;
  for (fs::path above = absolute.parent_path(); above.has_relative_path();
       above = above.parent_path()) {
    const int fd = ::open(above.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) continue;
    const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    ::close(fd);
    if (held)
      fail_file(folder, "inside " + above.string() +
                            ", which another iesrgs process is writing; wait for it to end (or "
                            "stop it) first");
  }
}

}  // namespace

FolderLock::FolderLock(const fs::path& folder) {
  refuse_inside_held_folder(folder);
  std::error_code ec;
  for (fs::path missing = folder; !missing.empty() && !fs::exists(missing, ec);
       missing = missing.parent_path())
    created_.push_back(missing);
  fs::create_directories(folder, ec);
  if (ec) fail_file(folder, "cannot create the output folder (" + ec.message() + ")");
  // A directory can be locked itself: no lock file is left among the outputs.
  fd_ = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    fail_file(folder, std::string("cannot open the output folder (") + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) {
    remove_stale_temporaries(folder);
    return;
  }
  const int error = errno;
  if (error != EWOULDBLOCK) return;  // no locks on this file system
  ::close(fd_);
  fd_ = -1;
  fail_file(folder,
            "in use by another iesrgs process; wait for it to end (or stop it) before writing "
            "to this folder again");
}

FolderLock::~FolderLock() {
  // Still holding the lock, so that no other process starts writing in between.
  std::error_code ec;
  for (const fs::path& folder : created_)
    if (!fs::remove(folder, ec)) break;  // not empty: this and every parent stay
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace iesrgs
