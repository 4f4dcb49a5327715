#include "core/log_once.hpp"

#include <spdlog/spdlog.h>

#include <mutex>
#include <set>

namespace iesrgs {

namespace {

bool first_time(const std::string& message) {
  static std::mutex mutex;
  static std::set<std::string> said;
  const std::lock_guard<std::mutex> lock(mutex);
  return said.insert(message).second;
}

}  // namespace

void warn_once(const std::string& message) {
  if (first_time(message)) spdlog::warn(message);
}

void debug_once(const std::string& message) {
  if (spdlog::should_log(spdlog::level::debug) && first_time(message)) spdlog::debug(message);
}

}  // namespace iesrgs
