// The CUDA Adam step against the same update on the host: built without fused multiply-adds, it
// rounds exactly as the host. Skipped without a CUDA device.
#include "gs/cuda/adam.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/cuda/device.hpp"
#include "core/cuda/device_array.hpp"
#include "gs/adam.hpp"

namespace iesrgs::gs::cuda {
namespace {

TEST(CudaAdam, MatchesTheHostUpdateOverSeveralSteps) {
  if (!iesrgs::cuda::device_available()) GTEST_SKIP() << "no CUDA device";
  const size_t n = 100003;  // not a multiple of the block size
  std::mt19937 rng(4);
  std::normal_distribution<float> normal(0, 1);
  std::vector<float> param(n), first(n, 0.f), second(n, 0.f), grad(n);
  for (float& p : param) p = normal(rng);
  iesrgs::cuda::DeviceArray<float> dparam(param), dfirst(first), dsecond(second), dgrad;
  for (int step = 1; step <= 5; ++step) {
    for (float& g : grad) g = 1e-3f * normal(rng);
    dgrad.upload(grad);
    const float step_size = float(1e-3 / (1 - std::pow(kAdamBeta1, step)));
    const float bias2_sqrt = float(std::sqrt(1 - std::pow(kAdamBeta2, step)));
    for (size_t i = 0; i < n; ++i)
      adam_update_value(param[i], grad[i], first[i], second[i], step_size, bias2_sqrt);
    adam_update(dparam.data(), dgrad.data(), dfirst.data(), dsecond.data(), int64_t(n), step_size,
                bias2_sqrt);
  }
  const std::vector<float> p = dparam.download(), m = dfirst.download(), v = dsecond.download();
  EXPECT_EQ(p, param);
  EXPECT_EQ(m, first);
  EXPECT_EQ(v, second);
}

}  // namespace
}  // namespace iesrgs::gs::cuda
