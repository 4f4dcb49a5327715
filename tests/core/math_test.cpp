#include <gtest/gtest.h>

#include "core/math.hpp"

namespace iesrgs {
namespace {

TEST(Math, EvenlySpacedIndicesStartAtTheFirstAndStayInRange) {
  EXPECT_EQ(evenly_spaced(10, 3), (std::vector<size_t>{0, 3, 6}));
  EXPECT_EQ(evenly_spaced(4, 4), (std::vector<size_t>{0, 1, 2, 3}));
  EXPECT_EQ(evenly_spaced(3, 7), (std::vector<size_t>{0, 1, 2}));
  EXPECT_TRUE(evenly_spaced(5, 0).empty());
  EXPECT_TRUE(evenly_spaced(0, 2).empty());
}

TEST(Math, QuaternionRoundTrip) {
  const double n = std::sqrt(0.3 * 0.3 + 0.5 * 0.5 + 0.1 * 0.1 + 0.8 * 0.8);
  const std::array<double, 4> q{0.3 / n, -0.5 / n, 0.1 / n, 0.8 / n};
  const Mat3 r = quat_to_rotation(q[0], q[1], q[2], q[3]);
  const Mat3 identity = r * r.transposed();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(identity(i, j), i == j ? 1 : 0, 1e-12);
  const auto back = rotation_to_quat(r);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(back[i], q[i], 1e-12);
}

TEST(Math, QuaternionIsNormalizedFirst) {
  // Twice a unit quaternion: the same rotation, as COLMAP reads it (and as the kernels' own).
  const Mat3 unit = quat_to_rotation(0.5, 0.5, -0.5, 0.5);
  const Mat3 doubled = quat_to_rotation(1, 1, -1, 1);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(doubled(i, j), unit(i, j));
}

TEST(Math, QuaternionOfEveryBranch) {
  // 180-degree turns about each axis exercise the branches where the trace is not positive.
  for (const auto& q :
       std::vector<std::array<double, 4>>{{0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}) {
    const auto back = rotation_to_quat(quat_to_rotation(q[0], q[1], q[2], q[3]));
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(std::abs(back[i]), std::abs(q[i]), 1e-12);
  }
}

}  // namespace
}  // namespace iesrgs
