#pragma once
// The internal geometric loss L_gem^I of the fusion stage: L1 between the render's expected depth
// (alpha-blended camera z over alpha) and I_depth, on the pixels where both saw a surface.
#include <cstddef>
#include <cstdint>

namespace iesrgs::loss {

// Pixels whose render covers them (alpha >= 0.5), the only ones the depth terms look at.
constexpr double kDepthCoverageAlpha = 0.5;

struct CoveredDepthL1 {
  double mean = 0;     // 0 where no pixel counts
  int64_t pixels = 0;  // those with alpha >= kDepthCoverageAlpha and reference > 0
};

// The mean over the covered pixels with a reference of |depth / alpha - reference|.
template <typename T>
CoveredDepthL1 covered_depth_l1(const T* depth, const T* alpha, const T* reference, size_t count);

// Writes to grad_depth and grad_alpha (count values each; zero off the pixels that count) the
// gradient of scale times the sum over those pixels of |depth / alpha - reference|; |t| has
// derivative 0 at t = 0, as in torch.
template <typename T>
void covered_depth_l1_backward(const T* depth, const T* alpha, const T* reference, size_t count,
                               T scale, T* grad_depth, T* grad_alpha);

}  // namespace iesrgs::loss
