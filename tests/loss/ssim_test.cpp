#include "loss/ssim.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "loss/loss_test_support.hpp"
#include "support/active_isa.hpp"
#include "support/compare.hpp"
#include "support/expect_error.hpp"

namespace iesrgs::loss {
namespace {

using loss_testing::numeric_gradient;
using loss_testing::random_values;
using loss_testing::reference_ssim_map;
using loss_testing::to_float;

// Random texture with flat patches, where E[x^2] - E[x]^2 would cancel badly in float: x bright
// and y dark in one block, both equal and bright in another.
struct ImagePair {
  ImageShape shape;
  std::vector<double> x, y;
};

ImagePair textured_pair(const ImageShape& shape, unsigned seed) {
  ImagePair pair{shape, random_values(shape.values(), seed),
                 random_values(shape.values(), seed + 1)};
  for (int r = 0; r < shape.height; ++r)
    for (int col = 0; col < shape.width; ++col)
      for (int c = 0; c < shape.channels; ++c) {
        const size_t i = (size_t(c) * shape.height + r) * shape.width + col;
        if (r < shape.height / 2 && col < shape.width / 2) {
          pair.x[i] = 0.95;
          pair.y[i] = 0.35;
        } else if (r >= shape.height / 2 && col >= shape.width / 2) {
          pair.x[i] = pair.y[i] = 0.8;
        }
      }
  return pair;
}

template <typename T>
std::vector<T> ssim_map(const std::vector<T>& x, const std::vector<T>& y, const ImageShape& shape,
                        double* mean = nullptr) {
  std::vector<T> map(shape.pixels());
  const double value = ssim<T>(x.data(), y.data(), shape, map.data(), nullptr);
  if (mean) *mean = value;
  return map;
}

template <typename T>
void expect_map_near(const std::vector<T>& map, const std::vector<double>& reference,
                     double tolerance) {
  ASSERT_EQ(map.size(), reference.size());
  double worst = 0;
  for (size_t p = 0; p < map.size(); ++p) worst = std::max(worst, std::abs(map[p] - reference[p]));
  EXPECT_LT(worst, tolerance);
}

// Sets the OpenMP thread count for one scope.
class ThreadCount {
 public:
  explicit ThreadCount(int threads) : saved_(omp_get_max_threads()) {
    omp_set_num_threads(threads);
  }
  ~ThreadCount() { omp_set_num_threads(saved_); }

 private:
  int saved_;
};

TEST(Ssim, FloatMatchesFloat64ReferenceIncludingFlatRegions) {
  const ImagePair pair = textured_pair({37, 29, 3}, 1);
  const std::vector<double> reference = reference_ssim_map(pair.x, pair.y, pair.shape);
  double mean = 0;
  const std::vector<float> map = ssim_map(to_float(pair.x), to_float(pair.y), pair.shape, &mean);
  expect_map_near(map, reference, 1e-5);
  EXPECT_NEAR(mean, loss_testing::mean(reference), 1e-6);
}

TEST(Ssim, DoubleMatchesFloat64Reference) {
  const ImagePair pair = textured_pair({24, 31, 2}, 2);
  double mean = 0;
  const std::vector<double> reference = reference_ssim_map(pair.x, pair.y, pair.shape);
  // The reference's E[x^2] - E[x]^2 leaves ~1e-12 of cancellation noise.
  expect_map_near(ssim_map(pair.x, pair.y, pair.shape, &mean), reference, 1e-10);
  EXPECT_NEAR(mean, loss_testing::mean(reference), 1e-10);
}

TEST(Ssim, ImagesSmallerThanTheWindowMatchReference) {
  for (const ImageShape shape : {ImageShape{1, 1, 1}, ImageShape{3, 2, 3}, ImageShape{10, 4, 1}}) {
    const ImagePair pair = textured_pair(shape, 3);
    expect_map_near(ssim_map(to_float(pair.x), to_float(pair.y), shape),
                    reference_ssim_map(pair.x, pair.y, shape), 1e-5);
  }
}

TEST(Ssim, IdenticalImagesGiveOne) {
  const ImageShape shape{19, 23, 3};
  const std::vector<float> x = to_float(random_values(shape.values(), 4));
  double mean = 0;
  for (float v : ssim_map(x, x, shape, &mean)) EXPECT_NEAR(v, 1.0f, 1e-6);
  EXPECT_NEAR(mean, 1.0, 1e-6);
}

TEST(Ssim, ConstantImagesKeepOnlyTheLuminanceTerm) {
  const ImageShape shape{30, 30, 1};
  const std::vector<double> x(shape.values(), 0.3), y(shape.values(), 0.7);
  const std::vector<float> map = ssim_map(to_float(x), to_float(y), shape);
  expect_map_near(map, reference_ssim_map(x, y, shape), 1e-5);
  // Away from the zero padding both variances vanish.
  const double luminance = (2 * 0.3 * 0.7 + kSsimC1) / (0.3 * 0.3 + 0.7 * 0.7 + kSsimC1);
  EXPECT_NEAR(map[15 * 30 + 15], luminance, 1e-6);
}

TEST(Ssim, BandsPerThreadDoNotChangeTheMap) {
  const ImagePair pair = textured_pair({17, 23, 3}, 5);
  const std::vector<float> x = to_float(pair.x), y = to_float(pair.y);
  std::vector<float> single;
  {
    ThreadCount threads(1);
    single = ssim_map(x, y, pair.shape);
  }
  for (int threads : {2, 5, 40}) {
    ThreadCount count(threads);
    EXPECT_EQ(ssim_map(x, y, pair.shape), single) << threads << " threads";
  }
}

// Gradient of sum_p weight[p] * map[p] by the double kernel.
std::vector<double> weighted_gradient(const ImagePair& pair, const std::vector<double>& weight) {
  std::vector<double> partials(ssim_partials_size(pair.shape));
  ssim<double>(pair.x.data(), pair.y.data(), pair.shape, nullptr, partials.data());
  std::vector<double> gradient(pair.shape.values(), 0.0);
  ssim_backward<double>(pair.x.data(), pair.y.data(), pair.shape, partials.data(), weight.data(),
                        gradient.data());
  return gradient;
}

TEST(Ssim, BackwardMatchesFiniteDifferences) {
  const ImagePair pair = textured_pair({13, 14, 3}, 6);
  const std::vector<double> weight = random_values(pair.shape.pixels(), 7, -1.0, 1.0);
  const auto weighted_sum = [&](const std::vector<double>& x) {
    const std::vector<double> map = reference_ssim_map(x, pair.y, pair.shape);
    double sum = 0;
    for (size_t p = 0; p < map.size(); ++p) sum += weight[p] * map[p];
    return sum;
  };
  loss_testing::expect_gradient_near(weighted_gradient(pair, weight),
                                     numeric_gradient(pair.x, weighted_sum), 1e-4);
}

TEST(Ssim, FloatBackwardMatchesDouble) {
  const ImagePair pair = textured_pair({41, 27, 3}, 8);
  const std::vector<double> weight(pair.shape.pixels(), 1.0 / double(pair.shape.pixels()));
  const std::vector<double> expected = weighted_gradient(pair, weight);

  const std::vector<float> x = to_float(pair.x), y = to_float(pair.y);
  std::vector<float> partials(ssim_partials_size(pair.shape));
  ssim<float>(x.data(), y.data(), pair.shape, nullptr, partials.data());
  std::vector<float> gradient(pair.shape.values(), 0.f);
  ssim_backward<float>(x.data(), y.data(), pair.shape, partials.data(), to_float(weight).data(),
                       gradient.data());
  // In the flat blocks the gradient is a difference of terms ~1/C2 larger than itself, which
  // float resolves to a few 1e-5 of the largest entry (as torch's float autograd does).
  EXPECT_LT(loss_testing::relative_max_error({gradient.begin(), gradient.end()}, expected), 1e-4);
}

// Mean, map, partials and gradient of a float SSIM pass under one instruction-set variant.
struct FloatPass {
  double mean;
  std::vector<float> map, partials, gradient;
};

FloatPass float_pass(cpu_isa::Isa isa, const ImagePair& pair, const std::vector<double>& weight) {
  const testing::ActiveIsa active(isa);
  const std::vector<float> x = to_float(pair.x), y = to_float(pair.y);
  FloatPass out{0, std::vector<float>(pair.shape.pixels()),
                std::vector<float>(ssim_partials_size(pair.shape)),
                std::vector<float>(pair.shape.values(), 0.5f)};
  out.mean = ssim<float>(x.data(), y.data(), pair.shape, out.map.data(), out.partials.data());
  ssim_backward<float>(x.data(), y.data(), pair.shape, out.partials.data(), to_float(weight).data(),
                       out.gradient.data());
  return out;
}

// The variants differ in vector width only: no fused multiply-adds, and each pixel's sums run in
// the same order, so their results are the same to the bit.
TEST(Ssim, InstructionSetVariantsGiveTheSameBits) {
  if (!cpu_isa::supported(cpu_isa::Isa::kAvx2))
    GTEST_SKIP() << "no AVX2 variant: not built (native, Debug or non-x86 build) or no CPU support";
  for (const ImageShape shape :
       {ImageShape{67, 45, 3}, ImageShape{5, 30, 1}, ImageShape{200, 9, 3}}) {
    SCOPED_TRACE(::testing::Message()
                 << shape.width << "x" << shape.height << "x" << shape.channels);
    const ImagePair pair = textured_pair(shape, 11);
    const std::vector<double> weight = random_values(shape.pixels(), 12, -1.0, 1.0);
    const FloatPass base = float_pass(cpu_isa::Isa::kBaseline, pair, weight);
    const FloatPass avx2 = float_pass(cpu_isa::Isa::kAvx2, pair, weight);
    EXPECT_EQ(avx2.mean, base.mean);
    EXPECT_TRUE(testing::same_bits(avx2.map, base.map));
    EXPECT_TRUE(testing::same_bits(avx2.partials, base.partials));
    EXPECT_TRUE(testing::same_bits(avx2.gradient, base.gradient));
  }
}

TEST(Ssim, BackwardAddsToTheGradient) {
  const ImagePair pair = textured_pair({12, 12, 1}, 9);
  const std::vector<double> weight(pair.shape.pixels(), 1.0);
  const std::vector<double> once = weighted_gradient(pair, weight);
  std::vector<double> partials(ssim_partials_size(pair.shape));
  ssim<double>(pair.x.data(), pair.y.data(), pair.shape, nullptr, partials.data());
  std::vector<double> twice = once;
  ssim_backward<double>(pair.x.data(), pair.y.data(), pair.shape, partials.data(), weight.data(),
                        twice.data());
  for (size_t i = 0; i < once.size(); ++i) EXPECT_DOUBLE_EQ(twice[i], 2 * once[i]);
}

TEST(Ssim, SupportHoldsTheWeightedTilesAndThoseWithinTheWindowOfThem) {
  constexpr int kTile = kSsimTile;
  const ImageShape shape{kTile + 13, 2 * kTile + 6, 3};  // 3 rows of 2 tiles, the last ones cut
  std::vector<float> weight(shape.pixels(), 0.f);
  const SsimSupport none = ssim_support(weight.data(), shape);
  EXPECT_EQ(none.tiles, 6u);
  EXPECT_TRUE(none.weighted.empty());
  EXPECT_TRUE(none.reached.empty());

  // Tile (0, 1); its window reaches tile rows 0 and 1, and tile column 1 only.
  weight[size_t(kTile - 2) * shape.width + kTile + 8] = -0.5f;
  const SsimSupport one = ssim_support(weight.data(), shape);
  const auto corners = [](const PixelBox& b) {
    return std::vector<int>{b.row0, b.row1, b.col0, b.col1};
  };
  ASSERT_EQ(one.weighted.size(), 1u);
  EXPECT_EQ(corners(one.weighted[0]), std::vector<int>({0, kTile, kTile, kTile + 13}));
  ASSERT_EQ(one.reached.size(), 2u);
  EXPECT_EQ(corners(one.reached[0]), corners(one.weighted[0]));
  EXPECT_EQ(corners(one.reached[1]), std::vector<int>({kTile, 2 * kTile, kTile, kTile + 13}));
}

// A weight that is zero but for a few pixels, some at tile and image borders.
std::vector<double> sparse_weight(const ImageShape& shape) {
  std::vector<double> weight(shape.pixels(), 0.0);
  constexpr int kTile = kSsimTile;
  for (const auto& [r, col] : std::vector<std::pair<int, int>>{
           {0, 0}, {kTile - 1, kTile}, {kTile + 1, 5}, {66, 44}, {40, 20}, {40, 21}})
    weight[size_t(r) * shape.width + col] = 0.1 + 0.01 * r;
  return weight;
}

TEST(Ssim, BoxesComputeTheWholeImageMapOnTheirPixelsOnly) {
  const ImagePair pair = textured_pair({45, 70, 3}, 10);
  std::vector<double> whole_partials(ssim_partials_size(pair.shape));
  std::vector<double> whole = ssim_map(pair.x, pair.y, pair.shape);
  ssim<double>(pair.x.data(), pair.y.data(), pair.shape, nullptr, whole_partials.data());

  const SsimSupport support = ssim_support(sparse_weight(pair.shape).data(), pair.shape);
  std::vector<double> map(pair.shape.pixels(), -7.0);
  std::vector<double> partials(whole_partials.size(), -7.0);
  const double sum = ssim_in<double>(pair.x.data(), pair.y.data(), pair.shape, support.weighted,
                                     map.data(), partials.data());
  double expected_sum = 0;
  size_t inside = 0;
  for (int r = 0; r < pair.shape.height; ++r)
    for (int col = 0; col < pair.shape.width; ++col) {
      const size_t p = size_t(r) * pair.shape.width + col;
      const bool in_box =
          std::any_of(support.weighted.begin(), support.weighted.end(), [&](const PixelBox& b) {
            return r >= b.row0 && r < b.row1 && col >= b.col0 && col < b.col1;
          });
      inside += in_box;
      EXPECT_EQ(map[p], in_box ? whole[p] : -7.0) << r << "," << col;
      if (in_box) expected_sum += whole[p] * pair.shape.channels;
      for (int i = 0; i < 3 * pair.shape.channels; ++i)
        EXPECT_EQ(partials[i * pair.shape.pixels() + p],
                  in_box ? whole_partials[i * pair.shape.pixels() + p] : -7.0);
    }
  EXPECT_GT(inside, 0u);
  EXPECT_LT(inside, pair.shape.pixels());
  EXPECT_NEAR(sum, expected_sum, 1e-9);
}

TEST(Ssim, BackwardOnTheReachedTilesEqualsTheWholeImageBackward) {
  const ImagePair pair = textured_pair({45, 70, 3}, 11);
  const std::vector<double> weight = sparse_weight(pair.shape);
  const std::vector<double> expected = weighted_gradient(pair, weight);

  const SsimSupport support = ssim_support(weight.data(), pair.shape);
  ASSERT_LT(support.reached.size(), support.tiles);
  std::vector<double> partials(ssim_partials_size(pair.shape), 0.0);
  ssim_in<double>(pair.x.data(), pair.y.data(), pair.shape, support.weighted, nullptr,
                  partials.data());
  std::vector<double> gradient(pair.shape.values(), 0.0);
  ssim_backward_in<double>(pair.x.data(), pair.y.data(), pair.shape, support.reached,
                           partials.data(), weight.data(), gradient.data());
  for (size_t i = 0; i < gradient.size(); ++i) EXPECT_NEAR(gradient[i], expected[i], 1e-15) << i;
}

TEST(Ssim, EmptyImageIsAnError) {
  const float value = 0;
  const std::string message = testing::error_message([&] {
    ssim<float>(&value, &value, ImageShape{0, 4, 3}, nullptr, nullptr);
  });
  EXPECT_EQ(message, "ssim: image size 0x4x3 is empty");
}

}  // namespace
}  // namespace iesrgs::loss
