#include "priors/keras_model.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/byte_reader.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs::priors::keras {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using Layer = LayersModel::Layer;
using Op = LayersModel::Op;
// Weight name as the manifest gives it ("<layer>/kernel") -> tensor of the manifest's shape.
using Weights = std::map<std::string, torch::Tensor>;

const json& member(const json& object, const char* key) {
  if (!object.is_object() || !object.contains(key))
    throw FormatError(fmt::format("missing '{}'", key));
  return object[key];
}

// The element count of `shape`, if it is valid and at most `available`.
std::optional<size_t> element_count(const std::vector<int64_t>& shape, size_t available) {
  size_t count = 1;
  for (int64_t size : shape) {
    if (size < 0 || (size > 0 && count > available / size)) return std::nullopt;
    count *= size;
  }
  return count;
}

void read_weight_group(const json& group, const fs::path& folder, Weights& weights) {
  std::string data;
  for (const json& shard : member(group, "paths"))
    data += read_file(folder / shard.get<std::string>());
  ByteReader reader(data);
  for (const json& spec : member(group, "weights")) {
    const auto name = member(spec, "name").get<std::string>();
    if (spec.contains("quantization") && !spec["quantization"].is_null())
      throw FormatError(fmt::format("weight '{}' is quantized (unsupported)", name));
    if (member(spec, "dtype") != "float32")
      throw FormatError(fmt::format("weight '{}' is not float32 (unsupported)", name));
    const auto shape = member(spec, "shape").get<std::vector<int64_t>>();
    const auto count = element_count(shape, reader.remaining() / sizeof(float));
    if (!count)
      throw FormatError(fmt::format("weight '{}' extends past the end of its shards", name));
    const size_t bytes = *count * sizeof(float);
    torch::Tensor tensor = torch::empty(shape, torch::kFloat);
    if (bytes) std::memcpy(tensor.data_ptr(), reader.take(bytes).data(), bytes);
    if (!torch::isfinite(tensor).all().item<bool>())
      throw FormatError(fmt::format("weight '{}' holds non-finite values (NaN or infinity)", name));
    weights[name] = tensor;
  }
  if (reader.remaining()) throw FormatError("weight shards hold more data than the manifest lists");
}

Weights read_weights(const json& manifest, const fs::path& folder) {
  Weights weights;
  for (const json& group : manifest) read_weight_group(group, folder, weights);
  return weights;
}

const torch::Tensor& weight(const Weights& weights, const std::string& name,
                            const std::vector<int64_t>& shape) {
  const auto found = weights.find(name);
  if (found == weights.end()) throw FormatError(fmt::format("weight '{}' missing", name));
  if (found->second.sizes() != torch::IntArrayRef(shape))
    throw FormatError(fmt::format("weight '{}' has shape {}, expected {}", name,
                                  fmt::streamed(found->second.sizes()),
                                  fmt::streamed(torch::IntArrayRef(shape))));
  return found->second;
}

void expect_config(const json& config, const std::string& key, const json& supported) {
  if (config.contains(key) && config[key] != supported)
    throw FormatError(fmt::format("unsupported {} {}", key, config[key].dump()));
}

bool is_relu(const json& config) {
  const auto activation = member(config, "activation").get<std::string>();
  if (activation != "linear" && activation != "relu")
    throw FormatError(fmt::format("unsupported activation '{}'", activation));
  return activation == "relu";
}

// TensorFlow's "same" padding at stride 1: the odd pixel of an even kernel goes after.
std::vector<int64_t> same_padding(int64_t height, int64_t width) {
  return {(width - 1) / 2, width / 2, (height - 1) / 2, height / 2};
}

void parse_conv(const json& config, const Weights& weights, int64_t in_channels, Layer& layer) {
  expect_config(config, "strides", {1, 1});
  expect_config(config, "dilation_rate", {1, 1});
  expect_config(config, "groups", 1);
  expect_config(config, "data_format", "channels_last");
  const auto kernel_size = member(config, "kernel_size").get<std::vector<int64_t>>();
  const auto filters = member(config, "filters").get<int64_t>();
  const auto padding = member(config, "padding").get<std::string>();
  if (kernel_size.size() != 2 || (padding != "same" && padding != "valid"))
    throw FormatError("unsupported kernel size or padding");
  const torch::Tensor kernel = weight(weights, layer.name + "/kernel",
                                      {kernel_size[0], kernel_size[1], in_channels, filters});
  layer.weight = kernel.permute({3, 2, 0, 1}).contiguous();  // HWIO -> OIHW
  if (member(config, "use_bias").get<bool>())
    layer.bias = weight(weights, layer.name + "/bias", {filters});
  layer.padding = padding == "same" ? same_padding(kernel_size[0], kernel_size[1])
                                    : std::vector<int64_t>{0, 0, 0, 0};
  layer.relu = is_relu(config);
  layer.channels = filters;
}

int64_t square_factor(const json& size) {
  const auto factors = size.get<std::vector<int64_t>>();
  if (factors.size() != 2 || factors[0] != factors[1] || factors[0] < 1)
    throw FormatError("only equal positive up-sampling factors are supported");
  return factors[0];
}

class GraphBuilder {
 public:
  explicit GraphBuilder(const Weights& weights) : weights_(weights) {}

  void add(const json& spec) {
    Layer layer;
    layer.name = member(spec, "name").get<std::string>();
    try {
      layer.inputs = inbound(member(spec, "inbound_nodes"));
      configure(member(spec, "class_name").get<std::string>(), member(spec, "config"), layer);
    } catch (const FormatError& e) {
      throw FormatError(fmt::format("layer '{}': {}", layer.name, e.what()));
    }
    if (!index_.emplace(layer.name, layers_.size()).second)
      throw FormatError(fmt::format("layer '{}' defined twice", layer.name));
    layers_.push_back(std::move(layer));
  }

  // The layers from `input` to `output`, which must be the first and the last that matter.
  std::vector<Layer> finish(const std::string& input, const std::string& output) {
    if (layers_.empty() || layers_.front().name != input || layers_.front().op != Op::Input)
      throw FormatError(fmt::format("input layer '{}' does not come first", input));
    const auto last = index_.find(output);
    if (last == index_.end()) throw FormatError(fmt::format("output layer '{}' missing", output));
    layers_.resize(last->second + 1);  // later layers cannot feed the output
    return std::move(layers_);
  }

 private:
  // Each layer is applied once: one node listing [layer, node 0, tensor 0, kwargs] per input.
  std::vector<size_t> inbound(const json& nodes) const {
    std::vector<size_t> inputs;
    if (nodes.empty()) return inputs;
    if (nodes.size() != 1) throw FormatError("layers applied more than once are not supported");
    for (const json& source : nodes[0]) {
      const auto found = index_.find(source.at(0).get<std::string>());
      if (found == index_.end() || source.at(1) != 0 || source.at(2) != 0)
        throw FormatError(fmt::format("unknown input {}", source.dump()));
      inputs.push_back(found->second);
    }
    return inputs;
  }

  int64_t input_channels(const Layer& layer, size_t index) const {
    return layers_[layer.inputs[index]].channels;
  }

  void expect_inputs(const Layer& layer, bool several) const {
    if (several ? layer.inputs.size() < 2 : layer.inputs.size() != 1)
      throw FormatError(fmt::format("wrong number of inputs ({})", layer.inputs.size()));
  }

  void configure(const std::string& kind, const json& config, Layer& layer) const {
    if (kind == "InputLayer") {
      if (!layer.inputs.empty() || !layers_.empty()) throw FormatError("misplaced input layer");
      layer.op = Op::Input;
      const json& shape = member(config, "batch_input_shape");
      if (!shape.is_array() || shape.size() != 4) throw FormatError("input is not an image batch");
      layer.channels = shape[3].get<int64_t>();
      return;
    }
    const bool merges = kind == "Concatenate" || kind == "Add";
    expect_inputs(layer, merges);
    layer.channels = input_channels(layer, 0);
    if (kind == "Conv2D") {
      layer.op = Op::Conv2D;
      parse_conv(config, weights_, layer.channels, layer);
    } else if (kind == "Activation") {
      layer.op = Op::Activation;
      layer.relu = is_relu(config);
    } else if (merges) {
      configure_merge(kind, config, layer);
    } else if (kind == "UpSampling2D") {
      expect_config(config, "interpolation", "nearest");
      layer.op = Op::UpSampling;
      layer.factor = square_factor(member(config, "size"));
    } else if (kind == "MultiplyBeta") {
      layer.op = Op::Scale;
      layer.scale = member(config, "beta").get<double>();
    } else if (kind.rfind("PixelShuffle", 0) == 0) {
      configure_depth_to_space(member(config, "scale").get<int64_t>(), layer);
    } else {
      throw FormatError(fmt::format("unsupported layer class '{}'", kind));
    }
  }

  void configure_merge(const std::string& kind, const json& config, Layer& layer) const {
    layer.op = kind == "Add" ? Op::Add : Op::Concatenate;
    if (layer.op == Op::Concatenate) {
      const auto axis = member(config, "axis").get<int64_t>();
      if (axis != 3 && axis != -1) throw FormatError("only channel concatenation is supported");
    }
    for (size_t i = 1; i < layer.inputs.size(); ++i) {
      if (layer.op == Op::Concatenate) {
        layer.channels += input_channels(layer, i);
      } else if (input_channels(layer, i) != layer.channels) {
        throw FormatError("added inputs differ in channels");
      }
    }
  }

  static void configure_depth_to_space(int64_t factor, Layer& layer) {
    if (factor < 1 || layer.channels % (factor * factor))
      throw FormatError("channels not divisible by the squared shuffle factor");
    layer.op = Op::DepthToSpace;
    layer.factor = factor;
    layer.channels /= factor * factor;
  }

  const Weights& weights_;
  std::vector<Layer> layers_;
  std::map<std::string, size_t> index_;
};

// The single input or output layer name of a functional model's config.
std::string endpoint(const json& config, const char* key) {
  const json& list = member(config, key);
  if (list.size() != 1)
    throw FormatError(fmt::format("models with several {} are not supported", key));
  return list.at(0).at(0).get<std::string>();
}

std::vector<Layer> parse_graph(const json& model_json, const Weights& weights) {
  const json& topology = member(model_json, "modelTopology");
  // Keras' converter nests the model under model_config; TensorFlow.js' own save does not.
  const json& model = topology.contains("model_config") ? topology["model_config"] : topology;
  const json& config = member(model, "config");
  GraphBuilder builder(weights);
  for (const json& layer : member(config, "layers")) builder.add(layer);
  return builder.finish(endpoint(config, "input_layers"), endpoint(config, "output_layers"));
}

// TensorFlow's depth_to_space in NHWC takes channel (i * r + j) * C + c to pixel offset (i, j).
torch::Tensor depth_to_space(const torch::Tensor& x, int64_t factor) {
  const int64_t batch = x.size(0), channels = x.size(1) / (factor * factor);
  const int64_t height = x.size(2), width = x.size(3);
  return x.reshape({batch, factor, factor, channels, height, width})
      .permute({0, 3, 4, 1, 5, 2})
      .reshape({batch, channels, height * factor, width * factor});
}

torch::Tensor convolve(const Layer& layer, const torch::Tensor& x) {
  const auto& pad = layer.padding;  // left, right, top, bottom
  const bool symmetric = pad[0] == pad[1] && pad[2] == pad[3];
  const torch::Tensor padded = symmetric ? x : torch::constant_pad_nd(x, pad);
  const std::vector<int64_t> inner =
      symmetric ? std::vector<int64_t>{pad[2], pad[0]} : std::vector<int64_t>{0, 0};
  torch::Tensor y = torch::conv2d(padded, layer.weight, layer.bias, 1, inner);
  return layer.relu ? y.relu_() : y;
}

torch::Tensor evaluate(const Layer& layer, const std::vector<torch::Tensor>& values) {
  const torch::Tensor& x = values[layer.inputs.at(0)];
  switch (layer.op) {
    case Op::Conv2D:
      return convolve(layer, x);
    case Op::Activation:
      return layer.relu ? torch::relu(x) : x;
    case Op::Concatenate: {
      std::vector<torch::Tensor> inputs;
      for (size_t index : layer.inputs) inputs.push_back(values[index]);
      return torch::cat(inputs, 1);
    }
    case Op::Add: {
      torch::Tensor sum = x + values[layer.inputs[1]];
      for (size_t i = 2; i < layer.inputs.size(); ++i) sum.add_(values[layer.inputs[i]]);
      return sum;
    }
    case Op::UpSampling:
      return torch::upsample_nearest2d(x, {x.size(2) * layer.factor, x.size(3) * layer.factor});
    case Op::Scale:
      return x * layer.scale;
    case Op::DepthToSpace:
      return depth_to_space(x, layer.factor);
    case Op::Input:
      break;
  }
  throw Error("keras layer '" + layer.name + "' cannot be evaluated");
}

}  // namespace

LayersModel::LayersModel(std::vector<Layer> layers)
    : layers_(std::move(layers)), last_use_(layers_.size()) {
  for (size_t i = 0; i < layers_.size(); ++i)
    for (size_t input : layers_[i].inputs) last_use_[input] = i;
}

LayersModel LayersModel::load(const fs::path& model_json) {
  try {
    const json document = json::parse(read_file(model_json));
    const Weights weights =
        read_weights(member(document, "weightsManifest"), model_json.parent_path());
    return LayersModel(parse_graph(document, weights));
  } catch (const FormatError& e) {
    fail_file(model_json, e.what());
  } catch (const json::exception& e) {
    fail_file(model_json, std::string("malformed model: ") + e.what());
  }
}

torch::Tensor LayersModel::forward(const torch::Tensor& input) const {
  if (input.dim() != 4 || input.size(1) != input_channels())
    fail("keras model: expected an input of shape (N, {}, H, W), got {}", input_channels(),
         fmt::streamed(input.sizes()));
  std::vector<torch::Tensor> values(layers_.size());
  values[0] = input;
  for (size_t i = 1; i < layers_.size(); ++i) {
    values[i] = evaluate(layers_[i], values);
    for (size_t source : layers_[i].inputs)
      if (last_use_[source] == i) values[source] = torch::Tensor();  // frees memory early
  }
  return values.back();
}

}  // namespace iesrgs::priors::keras
