#pragma once
// A fresh directory under the system temp folder, removed with everything in it at scope exit.
#include <filesystem>
#include <string>

namespace iesrgs::testing {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// Writes `bytes` to `path` (creating parent folders), for tests that build inputs by hand.
void write_text(const std::filesystem::path& path, const std::string& bytes);

}  // namespace iesrgs::testing
