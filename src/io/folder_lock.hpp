#pragma once
// An output folder is written by one process at a time: a second `train` or `run` into the same
// folder (a resume started while the first still runs, say) would interleave checkpoints, logs
// and cached stages.
#include <filesystem>
#include <optional>

#include "io/atomic_file.hpp"

namespace iesrgs {

// Creates `folder` if needed and holds an exclusive lock on it until destroyed. The kernel
// drops the lock when the process ends, however it ends, so a crash leaves nothing stale.
// Throws Error naming the folder when another process holds it, a folder above it or one of the
// folders up to four levels below it. On a file system without locks, the folder is used
// unlocked. Folders it created that are still empty when it is released, or when a signal ends
// the process (remove_temporaries_in_progress), are removed, so a command refused or stopped
// before its first output leaves no trace. Taking it removes the temporaries a
// killed writer left in the folder and below (remove_stale_temporaries).
class FolderLock {
 public:
  explicit FolderLock(const std::filesystem::path& folder);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  void take(const std::filesystem::path& folder);  // locks and checks the folder
  void release();

  int fd_ = -1;
  std::optional<CreatedFolders> created_;
};

}  // namespace iesrgs
