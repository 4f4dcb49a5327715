#pragma once
// Every output is written to "<name>.tmp-<pid>" first and renamed into place when complete, so
// an interrupted run never leaves a half-written file under the final name.
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace iesrgs {

// Calls write(tmp_path), then renames tmp_path to path. On any failure the temporary is removed,
// with the parent folders it created, and an Error naming `path` is thrown.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path&)>& write);

// Atomic text / binary file writes.
void write_file_atomically(const std::filesystem::path& path, const std::string& bytes);

// Files that belong together (a report's .json and .csv), written as write_file_atomically
// writes one: all of them complete before the first is renamed into place, so that a failure to
// write (a full disk) leaves none of them. When a later rename fails, those renamed before it are
// removed again where they replaced nothing. A signal that ends the process between two renames
// can leave the first ones.
void write_files_atomically(
    const std::vector<std::pair<std::filesystem::path, std::string>>& files);

// Checks before long work that `file` could be written (its folder made or there, a file created
// in it), leaving nothing behind; throws Error naming what stands in the way.
void require_writable(const std::filesystem::path& file);

// "write failed: <the system's reason>" for an errno a failed write left, or a guess without one.
std::string write_failure(int error);

// Closes `out`, written for `path` (inside write_atomically, which clears errno first); throws
// Error naming `path`, with the system's reason, when any write to it failed.
void close_written(std::ofstream& out, const std::filesystem::path& path);

// Levels of subfolders an output folder's own outputs reach: a run's rows/<row>/test/rgb/.
constexpr int kOutputFolderDepth = 4;

// Removes the temporaries that processes killed mid-write (kill -9, the OOM killer) left in
// `folder` and its subfolders down to kOutputFolderDepth levels: those of our outputs' kinds whose
// writer is gone.
void remove_stale_temporaries(const std::filesystem::path& folder);

// The same for the temporaries of `file` alone ("<file>.tmp-<pid>", beside it): for outputs
// written into any folder (export, eval), which no FolderLock takes.
void remove_stale_temporaries_of(const std::filesystem::path& file);

struct InProgressSlot;

// While alive, lists `path` for remove_temporaries_in_progress: a temporary being written, or a
// `folder` this process created for its outputs, removed only while still empty. One beyond the
// 64 slots, or a path of 4096 bytes or more, is not listed (the next command taking its folder
// removes a temporary).
class InProgress {
 public:
  explicit InProgress(const std::string& path, bool folder = false);
  ~InProgress();
  InProgress(const InProgress&) = delete;
  InProgress& operator=(const InProgress&) = delete;

 private:
  InProgressSlot* slot_ = nullptr;
};

// Creates `folder` and its missing parents, and lists those it created for
// remove_temporaries_in_progress while alive. Throws Error naming the folder when it cannot be
// made.
class CreatedFolders {
 public:
  explicit CreatedFolders(const std::filesystem::path& folder);
  CreatedFolders(const CreatedFolders&) = delete;
  CreatedFolders& operator=(const CreatedFolders&) = delete;

  // Removes the created folders still empty, innermost first, and stops listing them.
  void remove_empty();
  // Stops listing them and leaves them: another process may be about to write there.
  void forget();

 private:
  std::vector<std::filesystem::path> created_;  // the folder first, then its new parents
  std::vector<std::unique_ptr<InProgress>> listed_;
};

// Removes the temporaries this process is writing now, then the listed folders left empty.
// Async-signal-safe: for the handler that ends the process on a signal (end_on_signals), so that
// Ctrl-C leaves no half-written file, and no empty output folder.
void remove_temporaries_in_progress();

// Removes `file`, an earlier output about to be replaced, when it exists; returns whether it did.
// Throws Error naming the file when it cannot be removed, saying what left it (`left_by`, e.g.
// "left by an earlier render").
bool remove_earlier_output(const std::filesystem::path& file, std::string_view left_by);

// Whole file into memory; throws Error naming the file when it cannot be read.
std::string read_file(const std::filesystem::path& path);

}  // namespace iesrgs
