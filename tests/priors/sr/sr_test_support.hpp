#pragma once
// Fixtures and comparisons shared by the super-resolution tests. The fixtures are outputs of
// the authors' PyTorch modules, written by tests/data/priors/sr/make_sr_fixtures.py.
#include <torch/torch.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/image.hpp"
#include "io/image_tensor.hpp"
#include "io/resize.hpp"
#include "priors/sr/registry.hpp"
#include "priors/state_dict.hpp"
#include "support/tensor_files.hpp"

namespace iesrgs::priors::sr::sr_testing {

inline const std::filesystem::path kFixtures =
    std::filesystem::path(IESRGS_TEST_DATA) / "priors" / "sr";
inline const std::filesystem::path kReleasedWeights =
    std::filesystem::path(IESRGS_SHARED_DATA) / "weights" / "sr";

using testing::max_abs_difference;
using testing::read_npy_tensor;

// (1, 3, 20, 24): a crop of lego test view 0 after the protocol's bicubic x1/4, over white.
inline torch::Tensor lego_crop() {
  return read_npy_tensor(kFixtures / "lego_lr_crop.npy");
}

inline int64_t parameter_count(torch::nn::Module& module) {
  int64_t count = 0;
  for (const torch::Tensor& p : module.parameters()) count += p.numel();
  return count;
}

// Loads tiny_<model>_x2.pth into `net` (a small seeded configuration of the official layout)
// and compares its output on the lego crop with the official module's.
template <class Net>
float tiny_fixture_error(Net& net, const std::string& model) {
  const std::filesystem::path file = kFixtures / ("tiny_" + model + "_x2.pth");
  load_state_dict(*net, read_state_dict(file), file);
  torch::NoGradGuard no_grad;
  return max_abs_difference(net->forward(lego_crop()),
                            read_npy_tensor(kFixtures / ("tiny_" + model + "_x2_lego.npy")));
}

// The released x4 checkpoint `file` of `model` on the lego crop, against the official module.
inline float released_fixture_error(const std::string& model, const std::filesystem::path& file) {
  return max_abs_difference(make_sr_net(model, file, 4)->upscale(lego_crop()),
                            read_npy_tensor(kFixtures / (model + "_x4_lego.npy")));
}

// A lego test view as the x4 benchmark protocol has it: the 800x800 ground truth and its
// 200x200 bicubic downsample (resized with alpha, then composited, as the training images
// are), both over white, as (1, 3, H, W).
struct ProtocolView {
  torch::Tensor high, low;
};

inline ProtocolView lego_test_view(int index) {
  const float white[3] = {1.f, 1.f, 1.f};
  const Image8 rgba = read_image8(std::filesystem::path(IESRGS_SHARED_DATA) / "nerf_synthetic" /
                                  "lego" / "test" / ("r_" + std::to_string(index) + ".png"));
  return {to_tensor(composite_rgb(rgba, white)),
          to_tensor(composite_rgb(resize_bicubic(rgba, rgba.width / 4, rgba.height / 4), white))};
}

inline double psnr(const torch::Tensor& image, const torch::Tensor& reference) {
  const double mse = (image.clamp(0, 1) - reference).pow(2).mean().item<double>();
  return 10 * std::log10(1 / mse);
}

}  // namespace iesrgs::priors::sr::sr_testing
