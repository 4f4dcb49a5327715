#pragma once
// Fixture arrays as tensors, and the comparison the network tests make against them.
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <filesystem>
#include <limits>
#include <vector>

#include "io/npy.hpp"

namespace iesrgs::testing {

// A float32 .npy written by the fixture scripts, in its own shape.
inline torch::Tensor read_npy_tensor(const std::filesystem::path& path) {
  NpyArray array = read_npy(path);
  const std::vector<int64_t> shape(array.shape.begin(), array.shape.end());
  return torch::from_blob(array.data.data(), shape, torch::kFloat32).clone();
}

// The largest absolute difference; a test failure and infinity when the shapes differ.
inline double max_abs_difference(const torch::Tensor& a, const torch::Tensor& b) {
  EXPECT_EQ(a.sizes(), b.sizes());
  if (a.sizes() != b.sizes()) return std::numeric_limits<double>::infinity();
  return (a - b).abs().max().item<double>();
}

}  // namespace iesrgs::testing
