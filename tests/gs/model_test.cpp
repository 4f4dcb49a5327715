#include "gs/model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "gs/neighbors.hpp"
#include "gs/random_model.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::gs {
namespace {

std::vector<float> brute_force_knn(const std::vector<float>& p, int k) {
  const int n = int(p.size() / 3);
  std::vector<float> out(n);
  for (int i = 0; i < n; ++i) {
    std::vector<float> d;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      float s = 0;
      for (int a = 0; a < 3; ++a)
        s += (p[3 * i + a] - p[3 * j + a]) * (p[3 * i + a] - p[3 * j + a]);
      d.push_back(s);
    }
    std::sort(d.begin(), d.end());
    const int m = std::min<int>(k, int(d.size()));
    float sum = 0;
    for (int j = 0; j < m; ++j) sum += d[j];
    out[i] = sum / m;
  }
  return out;
}

TEST(GaussianModel, GridNearestNeighboursMatchBruteForce) {
  std::mt19937 rng(3);
  std::normal_distribution<float> normal(0.f, 1.f);
  std::vector<float> clustered, flat, far_outliers;
  for (int i = 0; i < 1500; ++i) {
    // Clusters of very different density, a flat sheet (one empty axis), and a cloud with 3 % of
    // its points up to 1e6 times further out, beyond the grid, as SfM clouds have them.
    const float spread = i % 3 == 0 ? 0.01f : 2.f;
    for (int a = 0; a < 3; ++a)
      clustered.push_back(normal(rng) * spread + (i % 3 == 0 ? 5.f : 0.f));
    flat.insert(flat.end(), {normal(rng), normal(rng), 0.f});
    const float reach = i % 33 == 0 ? std::pow(10.f, float(i % 7)) : 1.f;
    for (int a = 0; a < 3; ++a) far_outliers.push_back(normal(rng) * reach);
  }
  for (const auto* points : {&clustered, &flat, &far_outliers}) {
    const std::vector<float> fast = mean_knn_squared_distance(points->data(), 1500);
    const std::vector<float> slow = brute_force_knn(*points, 3);
    for (size_t i = 0; i < fast.size(); ++i) ASSERT_NEAR(fast[i], slow[i], 1e-6f * slow[i]) << i;
  }
}

TEST(GaussianModel, NearestNeighboursOfTinyClouds) {
  const float two[] = {0, 0, 0, 3, 4, 0};
  EXPECT_EQ(mean_knn_squared_distance(two, 2), (std::vector<float>{25, 25}));
  EXPECT_EQ(mean_knn_squared_distance(two, 1), (std::vector<float>{0}));
  EXPECT_TRUE(mean_knn_squared_distance(two, 0).empty());
}

// Points near the float limit: their spread overflows a float, which must not size the grid.
TEST(GaussianModel, NearestNeighboursOfPointsNearTheFloatLimit) {
  std::vector<float> points;
  for (int i = 0; i < 300; ++i)
    for (int a = 0; a < 3; ++a)
      points.push_back((i * 7 + a * 13) % 100 < 50 ? -1.75e38f : 1.75e38f);
  const std::vector<float> distances = mean_knn_squared_distance(points.data(), 300);
  ASSERT_EQ(distances.size(), 300u);
  EXPECT_EQ(distances[0], 0.f);  // its three nearest neighbours share its corner
}

TEST(GaussianModel, InitializesFromSfmPointsAs3dgs) {
  PointCloud cloud;
  // Four corners of a unit square plus a duplicate-free far point: 3 nearest known by hand.
  cloud.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  cloud.colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {128, 128, 128}};
  const GaussianModel m = model_from_point_cloud(cloud);
  ASSERT_EQ(m.size(), 4);
  // Each corner: neighbours at squared distances 1, 1, 2.
  const float expected_log_scale = std::log(std::sqrt(4.f / 3.f));
  EXPECT_TRUE(torch::allclose(m.log_scales, torch::full({4, 3}, expected_log_scale)));
  EXPECT_NEAR(m.sh_dc[0][0][0].item<float>(), 0.5f / 0.28209479f, 1e-5);
  EXPECT_NEAR(m.sh_dc[0][0][1].item<float>(), -0.5f / 0.28209479f, 1e-5);
  EXPECT_TRUE(torch::allclose(torch::sigmoid(m.opacity_logits), torch::full({4}, 0.1f)));
  EXPECT_TRUE(torch::equal(m.quats[2], torch::tensor({1.f, 0.f, 0.f, 0.f})));
  EXPECT_EQ(m.sh_rest.sizes(), (c10::IntArrayRef{4, 15, 3}));
  EXPECT_EQ(m.sh_rest.abs().sum().item<float>(), 0.f);
  EXPECT_EQ(m.active_sh_degree, 0);
  EXPECT_FALSE(m.filter_3d.defined());
  for (int p = 0; p < kParamCount; ++p) EXPECT_TRUE(m.param(Param(p)).requires_grad());
}

TEST(GaussianModel, CoincidentPointsGetTheMinimumScale) {
  const GaussianModel m = model_from_points({1, 2, 3, 1, 2, 3}, {0, 0, 0, 1, 1, 1});
  EXPECT_NEAR(m.log_scales[0][0].item<float>(), std::log(std::sqrt(1e-7f)), 1e-4);
}

TEST(GaussianModel, RandomBoxMatchesNerfSyntheticDefault) {
  // 3DGS's 100k points: the grid search must be fast.
  const GaussianModel m = model_from_random_box(100000, 1.3f, 0);
  ASSERT_EQ(m.size(), 100000);
  EXPECT_LE(m.means.abs().max().item<float>(), 1.3f);
  EXPECT_GT(m.means.abs().max().item<float>(), 1.29f);
  EXPECT_GE(m.sh_dc.min().item<float>(), 0.f);
  EXPECT_LT(m.sh_dc.max().item<float>(), 1.f / 255);
  // 100k uniform points in a 2.6^3 box sit about 0.04 apart.
  const float median_scale = m.log_scales.exp().median().item<float>();
  EXPECT_GT(median_scale, 0.02f);
  EXPECT_LT(median_scale, 0.06f);
  EXPECT_TRUE(torch::equal(model_from_random_box(10, 1.f, 7).means,
                           model_from_random_box(10, 1.f, 7).means));
}

TEST(GaussianModel, RandomBoxIsTheSamePointsMovedToItsCenter) {
  const Vec3 center{2, -1, 0.5};
  const torch::Tensor at_origin = model_from_random_box(1000, 0.5f, 3).means;
  const torch::Tensor moved = model_from_random_box(1000, 0.5f, 3, center).means;
  const torch::Tensor offset = torch::tensor({2.f, -1.f, 0.5f});
  EXPECT_TRUE(torch::allclose(moved, at_origin + offset, 0, 1e-6));
  EXPECT_LE((moved - offset).abs().max().item<float>(), 0.5f + 1e-6f);
}

// With a 3D filter and a lowered SH degree, which the PLY keeps and drops respectively.
GaussianModel filtered_model(int64_t n) {
  GaussianModel m = random_model(n);
  m.filter_3d = torch::rand({n});
  m.active_sh_degree = 2;
  return m;
}

TEST(GaussianModel, SavesAsPlyAndLoadsBackExactly) {
  testing::TempDir dir;
  const GaussianModel m = filtered_model(37);
  write_ply(dir / "m.ply", to_splat_cloud(m));
  const GaussianModel back = model_from_splat_cloud(read_ply(dir / "m.ply"));
  for (int p = 0; p < kParamCount; ++p)
    EXPECT_TRUE(torch::equal(back.param(Param(p)), m.param(Param(p)))) << p;
  EXPECT_TRUE(torch::equal(back.filter_3d, m.filter_3d));
  EXPECT_EQ(back.active_sh_degree, 3);
}

TEST(GaussianModel, LowerDegreeCloudsGetZeroHigherBands) {
  SplatCloud cloud = to_splat_cloud(filtered_model(5));
  cloud.sh_degree = 1;
  cloud.sh_rest.resize(5 * 3 * 3);
  cloud.filter_3d.clear();
  const GaussianModel m = model_from_splat_cloud(cloud);
  EXPECT_EQ(m.active_sh_degree, 1);
  EXPECT_FALSE(m.filter_3d.defined());
  EXPECT_EQ(m.sh_rest.narrow(1, 3, 12).abs().sum().item<float>(), 0.f);
  EXPECT_EQ(m.sh_rest[4][2][2].item<float>(), cloud.sh_rest[4 * 9 + 2 * 3 + 2]);

  cloud.opacity.pop_back();
  EXPECT_NE(testing::error_message([&] { model_from_splat_cloud(cloud); }).find("sizes disagree"),
            std::string::npos);
}

TEST(GaussianModel, CloneSharesNoStorage) {
  const GaussianModel original = filtered_model(4);
  const GaussianModel before = original.clone();
  GaussianModel copy = original.clone();
  {
    torch::NoGradGuard no_grad;  // in place, as the optimizer steps
    for (int p = 0; p < kParamCount; ++p) copy.param(Param(p)).add_(1);
    copy.filter_3d.add_(1);
  }
  for (int p = 0; p < kParamCount; ++p) {
    EXPECT_TRUE(torch::equal(original.param(Param(p)), before.param(Param(p)))) << p;
    EXPECT_TRUE(copy.param(Param(p)).requires_grad()) << p;
  }
  EXPECT_TRUE(torch::equal(original.filter_3d, before.filter_3d));
  EXPECT_EQ(copy.active_sh_degree, original.active_sh_degree);
}

}  // namespace
}  // namespace iesrgs::gs
