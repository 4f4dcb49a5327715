#include "priors/depth/depth_anything.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.hpp"
#include "priors/compute_device.hpp"

namespace iesrgs::priors::depth {

namespace {

// numpy's round, as the authors' constrain_to_multiple_of uses: halves go to the even neighbour,
// which std::nearbyint does in the default rounding mode.
int64_t multiple_at_least(double side, int minimum) {
  const double steps = side / kDinoPatchSize;
  const int64_t rounded = int64_t(std::nearbyint(steps)) * kDinoPatchSize;
  return rounded >= minimum ? rounded : int64_t(std::ceil(steps)) * kDinoPatchSize;
}

torch::Tensor channel_constants(const std::array<double, 3>& values,
                                const torch::TensorOptions& options) {
  return torch::tensor(c10::ArrayRef<double>(values), options).view({1, 3, 1, 1});
}

}  // namespace

DepthAnythingConfig depth_anything_config(const std::string& encoder) {
  if (encoder == "vits") return {{384, 12, 6}, {64, {48, 96, 192, 384}}, {2, 5, 8, 11}};
  if (encoder == "vitb") return {{768, 12, 12}, {128, {96, 192, 384, 768}}, {2, 5, 8, 11}};
  if (encoder == "vitl") return {{1024, 24, 16}, {256, {256, 512, 1024, 1024}}, {4, 11, 17, 23}};
  fail("unknown Depth Anything V2 encoder '{}' (expected vits, vitb or vitl)", encoder);
}

std::string depth_anything_encoder(const StateDict& weights, const std::filesystem::path& file) {
  const torch::Tensor* cls = find_weight(weights, "pretrained.cls_token", 3, file);
  if (!cls) fail_file(file, "not a Depth Anything V2 checkpoint (no pretrained.cls_token)");
  const int64_t width = cls->size(2);
  for (const char* encoder : {"vits", "vitb", "vitl"})
    if (depth_anything_config(encoder).vit.embed_dim == width) return encoder;
  fail_file(file, fmt::format("embedding width {} matches no released Depth Anything V2 encoder "
                              "(vits 384, vitb 768, vitl 1024)",
                              width));
}

DepthAnythingV2Impl::DepthAnythingV2Impl(const DepthAnythingConfig& config)
    : taken_blocks_(config.taken_blocks),
      pretrained_(register_module("pretrained", DinoVisionTransformer(config.vit))),
      depth_head_(register_module("depth_head", DptHead(config.vit.embed_dim, config.head))) {}

torch::Tensor DepthAnythingV2Impl::forward(const torch::Tensor& image) {
  const int patch = pretrained_->config().patch_size;
  const std::vector<torch::Tensor> tokens = pretrained_->intermediate_layers(image, taken_blocks_);
  return depth_head_(tokens, image.size(2) / patch, image.size(3) / patch).squeeze(1);
}

DepthAnythingV2 load_depth_anything(const DepthAnythingConfig& config, const StateDict& weights,
                                    const std::filesystem::path& file) {
  DepthAnythingV2 model(config);
  load_state_dict(*model, weights, file);
  model->eval();
  return model;
}

std::pair<int64_t, int64_t> network_input_size(int64_t height, int64_t width, int short_side) {
  const double scale = std::max(double(short_side) / height, double(short_side) / width);
  return {multiple_at_least(scale * height, short_side),
          multiple_at_least(scale * width, short_side)};
}

torch::Tensor network_input(const torch::Tensor& rgb, int short_side) {
  const auto [height, width] = network_input_size(rgb.size(2), rgb.size(3), short_side);
  // The authors resample a float64 image with cv2; doing it in double too keeps the difference
  // at cv2's single-precision filter weights.
  const torch::Tensor resized =
      torch::upsample_bicubic2d(rgb.to(torch::kFloat64), {height, width}, /*align_corners=*/false);
  const torch::Tensor mean = channel_constants({{0.485, 0.456, 0.406}}, resized.options());
  const torch::Tensor std = channel_constants({{0.229, 0.224, 0.225}}, resized.options());
  return ((resized - mean) / std).to(torch::kFloat32);
}

DepthAnythingNet::DepthAnythingNet(DepthAnythingV2 model, std::string name, int short_side)
    : model_(std::move(model)), name_(std::move(name)), short_side_(short_side) {}

torch::Tensor DepthAnythingNet::predict(const torch::Tensor& rgb) {
  if (rgb.dim() != 4 || rgb.size(0) != 1 || rgb.size(1) != 3)
    fail("{}: expected an RGB batch of shape (1, 3, H, W), got {}", name_,
         fmt::join(rgb.sizes(), "x"));
  torch::NoGradGuard no_grad;
  return on_compute_device(*model_, rgb, [&](const torch::Tensor& x) {
    const torch::Tensor depth = model_->forward(network_input(x, short_side_));
    return torch::upsample_bilinear2d(depth.unsqueeze(1), {rgb.size(2), rgb.size(3)},
                                      /*align_corners=*/true)[0][0];
  });
}

}  // namespace iesrgs::priors::depth
