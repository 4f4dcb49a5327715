#pragma once
// Running a TensorFlow.js layers model (model.json: the Keras topology and a weights manifest,
// plus binary weight shards) with LibTorch, without TensorFlow. The graph is evaluated in NCHW:
// Keras' channels-last kernels are transposed once at load time.
//
// Supported layers are those of the pre-trained UpscalerJS ESRGAN models: InputLayer, Conv2D
// (stride 1, "same" or "valid" padding, linear or relu activation), Activation (linear, relu),
// Concatenate (channel axis), Add, UpSampling2D (nearest), and the custom MultiplyBeta and
// PixelShuffle<r>x (TensorFlow's depth_to_space). Weights must be unquantized float32.
#include <torch/torch.h>

#include <filesystem>
#include <string>
#include <vector>

namespace iesrgs::priors::keras {

class LayersModel {
 public:
  // Reads `model_json` and the shards its manifest lists (paths relative to its folder). Throws
  // iesrgs::Error naming the file and the problem, for anything unsupported too.
  static LayersModel load(const std::filesystem::path& model_json);

  int64_t input_channels() const { return layers_.front().channels; }
  // (N, input_channels, H, W) float32 -> the output layer's value, NCHW.
  torch::Tensor forward(const torch::Tensor& input) const;

  enum class Op { Input, Conv2D, Activation, Concatenate, Add, UpSampling, Scale, DepthToSpace };
  struct Layer {
    std::string name;
    Op op = Op::Input;
    std::vector<size_t> inputs;    // indices of earlier layers
    int64_t channels = 0;          // of the output
    torch::Tensor weight, bias;    // Conv2D: OIHW kernel
    std::vector<int64_t> padding;  // Conv2D: left, right, top, bottom
    bool relu = false;             // Conv2D and Activation
    int64_t factor = 1;            // UpSampling and DepthToSpace
    double scale = 1;              // Scale
  };

 private:
  explicit LayersModel(std::vector<Layer> layers);

  std::vector<Layer> layers_;     // in evaluation order, the input first and the output last
  std::vector<size_t> last_use_;  // per layer, the last layer that reads its value
};

}  // namespace iesrgs::priors::keras
