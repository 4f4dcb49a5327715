#include "priors/depth/depth_preview.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.hpp"

namespace iesrgs::priors::depth {

namespace {

using Color = std::array<float, 3>;

// Evenly spaced stops whose brightness rises monotonically, so the order reads without a legend.
constexpr std::array<Color, 5> kRamp{{
    {0, 0, 4},
    {85, 15, 109},
    {187, 55, 84},
    {249, 140, 10},
    {252, 254, 164},
}};

void ramp_color(float t, uint8_t* rgb) {
  const float position = std::clamp(t, 0.f, 1.f) * (kRamp.size() - 1);
  const size_t stop = std::min(size_t(position), kRamp.size() - 2);
  const float f = position - float(stop);
  for (int c = 0; c < 3; ++c)
    rgb[c] = uint8_t(std::lround(kRamp[stop][c] + f * (kRamp[stop + 1][c] - kRamp[stop][c])));
}

}  // namespace

Image8 depth_preview(const torch::Tensor& depth) {
  if (depth.dim() != 2 || depth.numel() == 0)
    fail("depth preview: expected a non-empty (H, W) map, got shape {}",
         fmt::join(depth.sizes(), "x"));
  const torch::Tensor map = depth.detach().to(torch::kCPU, torch::kFloat32).contiguous();
  const float low = map.min().item<float>(), high = map.max().item<float>();
  const float scale = high > low ? 1.f / (high - low) : 0.f;
  Image8 out(int(map.size(1)), int(map.size(0)), 3);
  const float* values = map.data_ptr<float>();
  for (size_t p = 0; p < out.pixels(); ++p) ramp_color((values[p] - low) * scale, &out.data[p * 3]);
  return out;
}

}  // namespace iesrgs::priors::depth
