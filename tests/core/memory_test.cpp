#include "core/memory.hpp"

#include <gtest/gtest.h>

#include "support/expect_error.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;

TEST(Memory, AvailableAndPeakAreReadOnLinux) {
  EXPECT_GT(available_memory_bytes(), 0);
  EXPECT_GT(peak_memory_bytes(), 0);
}

TEST(Memory, RequiringMoreThanIsAvailableNamesWhatNeedsIt) {
  EXPECT_NO_THROW(require_memory(1 << 20, "a small buffer"));
  const int64_t too_much = available_memory_bytes() + (int64_t(1) << 30);
  const std::string message = error_message([&] { require_memory(too_much, "a huge buffer"); });
  EXPECT_TRUE(contains(message, "not enough memory: a huge buffer needs about")) << message;
}

}  // namespace
}  // namespace iesrgs
