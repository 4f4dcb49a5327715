#include "core/memory.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace iesrgs {
namespace {

TEST(Memory, AvailableAndPeakAreReadOnLinux) {
  EXPECT_GT(available_memory_bytes(), 0);
  EXPECT_GT(peak_memory_bytes(), 0);
}

TEST(Memory, RequiringMoreThanIsAvailableNamesWhatNeedsIt) {
  EXPECT_NO_THROW(require_memory(1 << 20, "a small buffer"));
  const int64_t too_much = available_memory_bytes() + (int64_t(1) << 30);
  try {
    require_memory(too_much, "a huge buffer");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not enough memory: a huge buffer needs about"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace iesrgs
