#pragma once
// Adam's update of one value, shared by the CPU optimizer and the CUDA kernel:
// torch::optim::Adam's update order and float arithmetic, so that all agree to rounding.
#include "core/hd.hpp"

namespace iesrgs::gs {

constexpr double kAdamBeta1 = 0.9, kAdamBeta2 = 0.999, kAdamEpsilon = 1e-15;

// step_size = lr / (1 - beta1^t), bias2_sqrt = sqrt(1 - beta2^t) at step t.
IESRGS_HD void adam_update_value(float& param, float grad, float& first, float& second,
                                 float step_size, float bias2_sqrt) {
  const float m = first * float(kAdamBeta1) + grad * float(1 - kAdamBeta1);
  const float v = second * float(kAdamBeta2) + grad * grad * float(1 - kAdamBeta2);
  first = m;
  second = v;
  param -= step_size * (m / (hd::sqrt(v) / bias2_sqrt + float(kAdamEpsilon)));
}

}  // namespace iesrgs::gs
