#include "core/torch_error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <new>
#include <system_error>

#include "core/error.hpp"

namespace iesrgs {
namespace {

template <typename Throw>
std::string message_of(Throw throw_it) {
  try {
    throw_it();
  } catch (...) {
    return current_exception_message();
  }
  return "nothing thrown";
}

// As LibTorch throws them: the message, then where it was raised and the backtrace. (The
// constructor taking a backtrace directly changed its type between LibTorch versions.)
c10::Error torch_error(const std::string& message) {
  return c10::Error(c10::SourceLocation{"torch_error", __FILE__, __LINE__}, message);
}

TEST(TorchError, FirstLineWithoutTheBacktrace) {
  const c10::Error error = torch_error("shape mismatch [2, 3]\nsecond line");
  EXPECT_NE(std::string(error.what()).find("Exception raised from"), std::string::npos);
  EXPECT_EQ(torch_error_line(error), "shape mismatch [2, 3]");
  EXPECT_EQ(message_of([&] { throw error; }), "shape mismatch [2, 3]");
}

TEST(TorchError, FailedLibTorchAllocationIsOutOfMemoryWithItsSize) {
  // As LibTorch's CPU allocator words it.
  const std::string words =
      "[enforce fail at alloc_cpu.cpp:75] err == 0. DefaultCPUAllocator: can't allocate memory: "
      "you tried to allocate 196608000000 bytes. Error code 12 (Cannot allocate memory)";
  EXPECT_EQ(message_of([&] { throw torch_error(words); }),
            "out of memory (LibTorch asked for 183.1 GiB)");
  const std::string smaller =
      "DefaultCPUAllocator: can't allocate memory: you tried to allocate "
      "12582912 bytes. Error code 12 (Cannot allocate memory)";
  EXPECT_EQ(message_of([&] { throw torch_error(smaller); }),
            "out of memory (LibTorch asked for 12.0 MiB)");
}

template <typename Throw>
bool out_of_memory(Throw throw_it) {
  try {
    throw_it();
  } catch (...) {
    return handling_out_of_memory();
  }
  return false;
}

TEST(TorchError, AllocationFailuresAreToldFromOtherErrors) {
  EXPECT_TRUE(out_of_memory([] { throw std::bad_alloc(); }));
  EXPECT_TRUE(out_of_memory([] {
    throw torch_error("DefaultCPUAllocator: can't allocate memory: you tried to allocate 8 bytes.");
  }));
  EXPECT_FALSE(out_of_memory([] { throw torch_error("shape mismatch [2, 3]"); }));
  EXPECT_FALSE(out_of_memory([] { fail("out of memory, says a message"); }));
}

// Said as the other errors are: the file, then the problem.
TEST(TorchError, FilesystemErrorsNameThePathFirst) {
  const std::filesystem::filesystem_error denied(
      "status", "run/render.json", std::make_error_code(std::errc::permission_denied));
  EXPECT_EQ(message_of([&] { throw denied; }), "run/render.json: Permission denied");
}

TEST(TorchError, OtherExceptionsKeepTheirMessage) {
  EXPECT_EQ(message_of([] { throw std::bad_alloc(); }), "out of memory");
  EXPECT_EQ(message_of([] { fail("scene.json: no frames"); }), "scene.json: no frames");
  EXPECT_EQ(message_of([] { throw 42; }), "unknown error");
}

}  // namespace
}  // namespace iesrgs
