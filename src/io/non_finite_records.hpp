#pragma once
// The records of a model or point file left out for holding a value that is not finite: a
// training that diverged in part (3DGS's does not check) still opens, as viewers open it,
// without its broken Gaussians. A file of broken records alone is refused.
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <string>

#include "core/error.hpp"

namespace iesrgs {

// What a reader does with a record holding a value that is not finite.
enum class NonFinite { LeaveOut, Refuse };

class NonFiniteRecords {
 public:
  // `what`: a record's name in the messages ("Gaussian", "point").
  NonFiniteRecords(const std::filesystem::path& name, const char* what,
                   NonFinite policy = NonFinite::LeaveOut)
      : name_(name), what_(what), policy_(policy) {}

  // One left out, or refused (an Error naming the file); `describe()` says why, and is called for
  // the first only.
  template <typename Describe>
  void add(Describe describe) {
    if (count_++ > 0) return;
    first_ = describe();
    if (policy_ == NonFinite::Refuse) fail_file(name_, first_);
  }

  // After the file's `total` records: a warning when some were left out, an Error naming the
  // file when all were.
  void report(size_t total) const {
    if (count_ == 0) return;
    if (count_ == total) fail_file(name_, fmt::format("every {} is left out: {}", what_, first_));
    spdlog::warn("{}: {} of {} {}s are left out for holding a value that is not finite (first, {})",
                 name_.string(), count_, total, what_, first_);
  }

 private:
  const std::filesystem::path& name_;
  const char* what_;
  NonFinite policy_;
  size_t count_ = 0;
  std::string first_;
};

}  // namespace iesrgs
