#include "core/torch_error.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>

namespace iesrgs {

namespace {

// LibTorch's CPU allocator says "... can't allocate memory: you tried to allocate N bytes ...".
std::string allocation_failure(const std::string& line) {
  if (line.find("can't allocate memory") == std::string::npos) return {};
  const std::string marker = "you tried to allocate ";
  const size_t at = line.find(marker);
  if (at == std::string::npos) return "out of memory";
  const double bytes = std::strtod(line.c_str() + at + marker.size(), nullptr);
  return bytes >= (1 << 30)
             ? fmt::format("out of memory (LibTorch asked for {:.1f} GiB)", bytes / (1 << 30))
             : fmt::format("out of memory (LibTorch asked for {:.1f} MiB)", bytes / (1 << 20));
}

}  // namespace

std::string torch_error_line(const c10::Error& error) {
  const std::string message = error.what_without_backtrace();
  return message.substr(0, message.find('\n'));
}

bool handling_out_of_memory() {
  try {
    throw;
  } catch (const std::bad_alloc&) {
    return true;
  } catch (const c10::Error& e) {
    return !allocation_failure(torch_error_line(e)).empty();
  } catch (...) {
    return false;
  }
}

std::string current_exception_message() {
  try {
    throw;
  } catch (const std::bad_alloc&) {
    return "out of memory";
  } catch (const c10::Error& e) {
    const std::string line = torch_error_line(e);
    const std::string oom = allocation_failure(line);
    return oom.empty() ? line : oom;
  } catch (const std::filesystem::filesystem_error& e) {
    // "filesystem error: status: Permission denied [a/b]" as the other errors say it: the file,
    // then the problem.
    return e.path1().empty() ? e.what() : e.path1().string() + ": " + e.code().message();
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown error";
  }
}

}  // namespace iesrgs
