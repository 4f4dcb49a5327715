#include "io/image_tensor.hpp"

#include <algorithm>
#include <sstream>

#include "core/error.hpp"

namespace iesrgs {

namespace {

// The planar float view of a checked batch, as an (H, W, 3) tensor.
torch::Tensor interleaved(const torch::Tensor& rgb) {
  check_rgb_batch(rgb, "image conversion");
  return rgb[0].permute({1, 2, 0});
}

std::string shape_of(const torch::Tensor& tensor) {
  if (!tensor.defined()) return "no tensor";
  std::ostringstream text;
  text << tensor.sizes();
  return text.str();
}

}  // namespace

torch::Tensor to_tensor(const Image& rgb) {
  if (rgb.channels != 3) fail("image conversion: expected 3 channels, got {}", rgb.channels);
  // from_blob borrows the image's storage; the clone owns its own (contiguous() would not copy a
  // 1x1 image, whose permuted view already counts as contiguous).
  const torch::Tensor hwc = torch::from_blob(const_cast<float*>(rgb.data.data()),
                                             {rgb.height, rgb.width, 3}, torch::kFloat32);
  return hwc.permute({2, 0, 1}).unsqueeze(0).clone(torch::MemoryFormat::Contiguous);
}

Image to_image(const torch::Tensor& rgb) {
  const torch::Tensor hwc = interleaved(rgb);
  Image out(int(hwc.size(1)), int(hwc.size(0)), 3);
  torch::from_blob(out.data.data(), hwc.sizes(), torch::kFloat32).copy_(hwc);
  return out;
}

Image8 to_image8(const torch::Tensor& rgb) {
  const torch::Tensor hwc = interleaved(rgb);
  Image8 out(int(hwc.size(1)), int(hwc.size(0)), 3);
  const torch::Tensor bytes = torch::from_blob(out.data.data(), hwc.sizes(), torch::kUInt8);
  // A band of rows at a time, so a large output never needs a full-size float temporary.
  constexpr int64_t kRows = 64;
  for (int64_t y = 0; y < hwc.size(0); y += kRows) {
    const int64_t rows = std::min(kRows, hwc.size(0) - y);
    torch::Tensor band = hwc.narrow(0, y, rows).clamp(0.f, 1.f);
    // Halves round up, as lround does in to_8bit for these non-negative values.
    bytes.narrow(0, y, rows).copy_(band.mul_(255.f).add_(0.5f).floor_());
  }
  return out;
}

void check_rgb_batch(const torch::Tensor& rgb, const std::string& model) {
  if (!rgb.defined() || rgb.dim() != 4 || rgb.size(0) != 1 || rgb.size(1) != 3)
    fail("{}: expected an RGB batch of shape (1, 3, H, W), got {}", model, shape_of(rgb));
  if (rgb.scalar_type() != torch::kFloat32 || !rgb.device().is_cpu())
    fail("{}: expected a float32 CPU tensor", model);
  if (rgb.size(2) < 1 || rgb.size(3) < 1) fail("{}: empty image", model);
}

}  // namespace iesrgs
