#include "io/folder_lock.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>
#include <system_error>
#include <thread>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

// Whether another process holds `folder`. The probe's own shared lock lasts an instant, which
// FolderLock's retries ride out.
bool held_elsewhere(const fs::path& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return held;
}

[[noreturn]] void fail_held(const fs::path& folder, const char* relation, const fs::path& held) {
  fail_file(folder, fmt::format("{} {}, which another process is writing (an iesrgs command, "
                                "say); wait for it to end (or stop it) first",
                                relation, held.string()));
}

// A folder inside one that another process holds (a run's stage folders, say) is that process's
// to write: a `train` or `render` there would change what the run has cached under it.
void refuse_inside_held_folder(const fs::path& folder) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(folder, ec);
  if (ec) return;
  for (fs::path above = absolute.parent_path(); above.has_relative_path();
       above = above.parent_path())
    if (held_elsewhere(above)) fail_held(folder, "inside", above);
}

// And the other way round: a run must not write over a stage folder that a `train` or `render`
// is writing, down to the folders of its outputs, as deep as remove_stale_temporaries looks.
void refuse_around_held_folder(const fs::path& folder) {
  std::error_code ec;
  fs::recursive_directory_iterator it(folder, fs::directory_options::skip_permission_denied, ec);
  for (; !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it.depth() + 1 >= kOutputFolderDepth) it.disable_recursion_pending();
    if (it->is_directory(ec) && !it->is_symlink(ec) && held_elsewhere(it->path()))
      fail_held(folder, "above", it->path());
  }
}

bool lock_exclusively(int fd) {
  constexpr int kTries = 20;  // 0.2 s: a neighbour's probe of this folder ends well before
  for (int i = 0; i < kTries; ++i) {
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return true;
    if (errno != EWOULDBLOCK) return true;  // no locks on this file system
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace

FolderLock::FolderLock(const fs::path& folder) {
  refuse_inside_held_folder(folder);
  created_.emplace(folder);
  try {
    take(folder);
  } catch (...) {
    release();  // the destructor does not run for a constructor that throws
    throw;
  }
}

FolderLock::~FolderLock() {
  release();
}

void FolderLock::take(const fs::path& folder) {
  // A directory can be locked itself: no lock file is left among the outputs.
  fd_ = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    fail_file(folder, std::string("cannot open the output folder (") + std::strerror(errno) + ")");
  if (!lock_exclusively(fd_)) {
    created_->forget();  // another process holds them now, and may be about to write there
    fail_file(folder,
              "in use by another process (an iesrgs command, say); wait for it to end (or "
              "stop it) before writing to this folder again");
  }
  refuse_around_held_folder(folder);
  remove_stale_temporaries(folder);
}

void FolderLock::release() {
  // Still holding the lock (or never having got it, when it created nothing), so that no other
  // process starts writing in between.
  if (created_) created_->remove_empty();
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace iesrgs
