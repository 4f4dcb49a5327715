#pragma once
// A model of n Gaussians with standard-normal parameters (SH degree 3 layout) for the gs tests.
#include <torch/torch.h>

#include "gs/model.hpp"

namespace iesrgs::gs {

inline GaussianModel random_model(int64_t n) {
  GaussianModel m;
  m.set_params({torch::randn({n, 3}), torch::randn({n, 1, 3}), torch::randn({n, 15, 3}),
                torch::randn({n}), torch::randn({n, 3}), torch::randn({n, 4})});
  return m;
}

}  // namespace iesrgs::gs
