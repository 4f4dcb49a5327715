#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string_view>
#include <system_error>

#include "core/error.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

// The temporaries being written, and the folders created for outputs, for a signal handler to
// remove. Each slot keeps its own copy of the name, so that a handler on another thread only ever
// reads a name, never memory its writer has freed.
struct InProgressSlot {
  std::atomic<bool> taken{false};
  std::atomic<bool> listed{false};  // `name` is complete
  bool folder = false;
  char name[4096];
};

namespace {

constexpr std::string_view kTemporaryMark = ".tmp-";

std::array<InProgressSlot, 64> in_progress;

fs::path parent_folder(const fs::path& path) {
  return path.has_parent_path() ? path.parent_path() : fs::path(".");
}

void move_into_place(const fs::path& tmp, const fs::path& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) fail_file(path, "cannot move finished file into place: " + ec.message());
}

fs::path temporary_path(const fs::path& path) {
  return path.string() + std::string(kTemporaryMark) + std::to_string(::getpid());
}

using Writer = std::function<void(const fs::path&)>;

// Every write here: each writer fills its file's temporary, all of them before the first rename.
// On a failure the temporaries go, the renamed files that replaced nothing, and the folders made
// for them.
void write_set(const std::vector<std::pair<fs::path, Writer>>& files) {
  std::vector<std::unique_ptr<CreatedFolders>> folders;
  std::vector<std::unique_ptr<InProgress>> listed;
  std::vector<fs::path> temporaries;
  std::vector<bool> replaces;  // an earlier output, which a removal could not bring back
  size_t renamed = 0;
  try {
    for (const auto& [path, write] : files) {
      folders.push_back(std::make_unique<CreatedFolders>(parent_folder(path)));
      temporaries.push_back(temporary_path(path));
      listed.push_back(std::make_unique<InProgress>(temporaries.back().string()));
      errno = 0;  // for close_written
      write(temporaries.back());
    }
    std::error_code ec;
    for (const auto& [path, write] : files)
      replaces.push_back(fs::exists(fs::symlink_status(path, ec)));
    for (; renamed < files.size(); ++renamed)
      move_into_place(temporaries[renamed], files[renamed].first);
  } catch (...) {
    std::error_code ec;
    for (size_t i = 0; i < temporaries.size(); ++i)
      if (i >= renamed || !replaces[i])
        fs::remove(i < renamed ? files[i].first : temporaries[i], ec);
    for (auto folder = folders.rbegin(); folder != folders.rend(); ++folder)
      (*folder)->remove_empty();
    throw;
  }
}

// A temporary of one of our outputs, "<name>.<ext>.tmp-<pid>" as temporary_path names them,
// whose writer is no longer running. Other programs' files never match: only the extensions of
// what iesrgs writes count.
bool is_stale_temporary(const fs::path& path) {
  const std::string name = path.filename().string();
  const size_t mark = name.rfind(kTemporaryMark);
  if (mark == std::string::npos || mark == 0) return false;
  const std::string digits = name.substr(mark + kTemporaryMark.size());
  if (digits.empty() || digits.size() > 9 ||
      !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); }))
    return false;
  const std::string extension = fs::path(name.substr(0, mark)).extension().string();
  const bool ours = extension == ".pt" || extension == ".ply" || extension == ".png" ||
                    extension == ".npy" || extension == ".json" || extension == ".csv" ||
                    extension == ".spz" || extension == ".splat" || extension == ".md" ||
                    extension == ".html";
  const pid_t writer = pid_t(std::stol(digits));
  return ours && writer != ::getpid() && ::kill(writer, 0) != 0 && errno == ESRCH;
}

}  // namespace

void write_atomically(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  write_set({{path, write}});
}

void remove_stale_temporaries(const fs::path& folder) {
  std::error_code walk;
  for (fs::recursive_directory_iterator
           it(folder, fs::directory_options::skip_permission_denied, walk),
       end;
       !walk && it != end; it.increment(walk)) {
    std::error_code ec;  // an entry that cannot be checked or removed is left alone
    if (it->is_directory(ec) && it.depth() >= kOutputFolderDepth) it.disable_recursion_pending();
    if (it->is_regular_file(ec) && is_stale_temporary(it->path())) fs::remove(it->path(), ec);
  }
}

void remove_stale_temporaries_of(const fs::path& file) {
  const std::string prefix = file.filename().string() + std::string(kTemporaryMark);
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::error_code walk;
  for (fs::directory_iterator it(folder, walk), end; !walk && it != end; it.increment(walk)) {
    std::error_code ec;  // as above: what cannot be checked or removed is left alone
    if (it->path().filename().string().rfind(prefix, 0) == 0 && it->is_regular_file(ec) &&
        is_stale_temporary(it->path()))
      fs::remove(it->path(), ec);
  }
}

InProgress::InProgress(const std::string& path, bool folder) {
  if (path.size() >= sizeof(InProgressSlot::name)) return;
  for (InProgressSlot& slot : in_progress) {
    bool free = false;
    if (!slot.taken.compare_exchange_strong(free, true)) continue;
    std::memcpy(slot.name, path.c_str(), path.size() + 1);
    slot.folder = folder;
    slot.listed = true;
    slot_ = &slot;
    return;
  }
}

InProgress::~InProgress() {
  if (!slot_) return;
  slot_->listed = false;
  slot_->taken = false;
}

// One level at a time, so that only the folders this call made are listed (not one another
// process made meanwhile, nor a link to nothing, which counts as missing to fs::exists).
CreatedFolders::CreatedFolders(const fs::path& folder) {
  std::error_code ec;
  fs::path path;
  for (const fs::path& part : folder) {
    if (part.empty()) continue;  // a trailing separator
    path /= part;
    if (::mkdir(path.c_str(), 0777) == 0) {
      created_.insert(created_.begin(), path);
      listed_.push_back(std::make_unique<InProgress>(fs::absolute(path).string(), true));
    } else if (const int error = errno; error != EEXIST && !fs::is_directory(path, ec)) {
      // Not EEXIST alone: NFS answers mkdir of an existing folder it may not write in with EACCES.
      const std::string reason = std::strerror(error);
      remove_empty();  // the parents made before the failure
      fail_file(path, "cannot create the folder (" + reason + ")");
    }
  }
  if (!fs::is_directory(folder, ec)) {
    remove_empty();
    fail_file(folder, "cannot create the folder: something else has its name");
  }
}

void CreatedFolders::remove_empty() {
  // rmdir: never a file or a link, and never a folder that holds something.
  for (const fs::path& folder : created_)
    if (::rmdir(folder.c_str()) != 0) break;  // not empty: this and every parent stay
  forget();
}

void CreatedFolders::forget() {
  created_.clear();
  listed_.clear();
}

void remove_temporaries_in_progress() {
  for (const InProgressSlot& slot : in_progress)
    if (slot.listed && !slot.folder) ::unlink(slot.name);
  // Folders once the files in them are gone, and again while one goes: a parent listed before
  // its child is empty only after it.
  for (bool removed = true; removed;) {
    removed = false;
    for (const InProgressSlot& slot : in_progress)
      if (slot.listed && slot.folder && ::rmdir(slot.name) == 0) removed = true;
  }
}

void write_file_atomically(const fs::path& path, const std::string& bytes) {
  write_files_atomically({{path, bytes}});
}

void write_files_atomically(const std::vector<std::pair<fs::path, std::string>>& files) {
  std::vector<std::pair<fs::path, Writer>> writers;
  for (const auto& [path, bytes] : files)
    writers.emplace_back(path, [&path = path, &bytes = bytes](const fs::path& tmp) {
      std::ofstream out(tmp, std::ios::binary);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      close_written(out, path);
    });
  write_set(writers);
}

void require_writable(const fs::path& file) {
  CreatedFolders folders(parent_folder(file));
  const fs::path tmp = temporary_path(file);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int error = errno;
  if (fd >= 0) {
    ::close(fd);
    ::unlink(tmp.c_str());
  }
  folders.remove_empty();
  if (fd < 0) fail_file(file, fmt::format("cannot be written ({})", std::strerror(error)));
}

std::string write_failure(int error) {
  return error ? fmt::format("write failed: {}", std::strerror(error))
               : "write failed (disk full or not writable?)";
}

void close_written(std::ofstream& out, const fs::path& path) {
  if (out) errno = 0;  // else the failed write's, as a stream makes no calls once it has failed
  out.close();
  if (!out) fail_file(path, write_failure(errno));
}

bool remove_earlier_output(const fs::path& file, std::string_view left_by) {
  std::error_code ec;
  // Not there, or its folder not a folder: nothing to remove, and the output's write will say
  // what stands in its way (a read-only disk answers even an absent file's removal with EROFS).
  if (!fs::exists(fs::symlink_status(file, ec))) return false;
  const bool removed = fs::remove(file, ec);
  if (ec) fail_file(file, fmt::format("{}, and cannot be removed: {}", left_by, ec.message()));
  return removed;
}

std::string read_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail_file(path, "file not found");
  if (fs::is_directory(path, ec)) fail_file(path, "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_file(path, "cannot open for reading");
  // Appended into a string reserved at the file's size (pipes have none): a stringstream grows by
  // doubling and then copies, and peaked at twice the size of the file (1.4 GB for 0.7 GB).
  std::string bytes;
  if (const auto size = fs::file_size(path, ec); !ec) bytes.reserve(size);
  std::array<char, 1 << 16> chunk;
  while (in.read(chunk.data(), chunk.size()) || in.gcount() > 0)
    bytes.append(chunk.data(), in.gcount());
  if (in.bad()) fail_file(path, "read error");
  return bytes;
}

}  // namespace iesrgs
