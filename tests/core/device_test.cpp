#include "core/device.hpp"

#include <gtest/gtest.h>
#include <torch/cuda.h>

#include "support/expect_error.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;

TEST(Device, CpuIsAlwaysThere) {
  EXPECT_EQ(parse_device("cpu"), torch::Device(torch::kCPU));
  EXPECT_TRUE(contains(describe_device(torch::kCPU), "threads"));
}

TEST(Device, AutoTakesTheGpuOnlyWhereItCanBeUsed) {
  const bool usable = cuda_kernels_built() && torch::cuda::is_available();
  EXPECT_EQ(parse_device("auto").is_cuda(), usable);
}

TEST(Device, CudaWithoutAUsableGpuSaysWhy) {
  if (cuda_kernels_built() && torch::cuda::is_available()) {
    EXPECT_TRUE(parse_device("cuda").is_cuda());
    return;
  }
  const std::string message = error_message([] { parse_device("cuda"); });
  EXPECT_TRUE(contains(message, "--device cuda: ")) << message;
  EXPECT_TRUE(contains(message, cuda_kernels_built() ? "LibTorch sees no usable GPU"
                                                     : "this build has no CUDA kernels"))
      << message;
}

TEST(Device, UnknownNamesAreErrors) {
  EXPECT_EQ(error_message([] { parse_device("gpu"); }),
            "--device: unknown device 'gpu' (cpu, cuda or auto)");
}

// Library users and the tests train on the CPU unless they choose otherwise.
TEST(Device, TheComputeDeviceIsTheCpuUnlessSet) {
  EXPECT_TRUE(compute_device().is_cpu());
}

}  // namespace
}  // namespace iesrgs
