#pragma once
// A model of one opaque red Gaussian at the origin and a camera 4 units in front of it, for tests
// of what is rendered from a model.
#include <torch/torch.h>

#include <cmath>

#include "gs/model.hpp"
#include "support/looking_cameras.hpp"

namespace iesrgs::testing {

struct OneGaussian {
  gs::GaussianModel model;
  Camera camera = camera_at({0, -4, 0}, {0, 0, 0});  // 64x48, named "v"

  OneGaussian() {
    model.set_params({torch::zeros({1, 3}), torch::tensor({1.7f, -1.7f, -1.7f}).view({1, 1, 3}),
                      torch::zeros({1, 15, 3}), torch::full({1}, 6.0f),
                      torch::full({1, 3}, std::log(0.3f)), torch::tensor({{1.f, 0.f, 0.f, 0.f}})});
    camera.name = "v";
  }
};

}  // namespace iesrgs::testing
