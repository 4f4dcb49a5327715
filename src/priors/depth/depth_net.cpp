#include "priors/depth/depth_net.hpp"

#include <spdlog/spdlog.h>

#include "core/error.hpp"
#include "priors/depth/depth_anything.hpp"

namespace iesrgs::priors::depth {

namespace {

const std::string kDepthAnything = "depth-anything-v2";

// "depth-anything-v2-vits" -> "vits"; "depth-anything-v2" -> "" (take it from the checkpoint).
std::string requested_encoder(const std::string& model) {
  if (model == kDepthAnything) return "";
  const std::string prefix = kDepthAnything + "-";
  const std::string encoder = model.substr(std::min(prefix.size(), model.size()));
  if (model.compare(0, prefix.size(), prefix) != 0 ||
      (encoder != "vits" && encoder != "vitb" && encoder != "vitl"))
    fail(
        "unknown depth model '{}' (expected depth-anything-v2, depth-anything-v2-vits, "
        "depth-anything-v2-vitb, depth-anything-v2-vitl or none)",
        model);
  return encoder;
}

}  // namespace

std::unique_ptr<DepthNet> make_depth_net(const std::string& model,
                                         const std::filesystem::path& weights) {
  if (model == "none") {
    spdlog::info("depth model: none, so the external depth loss is off");
    return nullptr;
  }
  const std::string requested = requested_encoder(model);
  if (weights.empty())
    fail(
        "{} needs the authors' checkpoint (depth_anything_v2_{}.pth) as its weights: give its "
        "path with --depth-weights (--weights in iesrgs depth)",
        model, requested.empty() ? "vitl" : requested);
  // The metric models have the relative models' names and shapes, so only the file name tells:
  // their head ends in a sigmoid times max_depth where the relative one has a ReLU.
  if (weights.filename().string().find("metric") != std::string::npos)
    fail_file(
        weights,
        "a Depth Anything V2 metric-depth checkpoint, which this build does not run (its head "
        "differs from the relative model's only in layers without weights); the depth prior "
        "is relative: use the authors' depth_anything_v2_<encoder>.pth");
  const StateDict state = read_state_dict(weights);
  const std::string encoder = depth_anything_encoder(state, weights);
  if (!requested.empty() && encoder != requested)
    fail_file(weights,
              fmt::format("holds a Depth Anything V2 {} model, not the {} that {} asks for",
                          encoder, requested, model));
  DepthAnythingV2 network = load_depth_anything(depth_anything_config(encoder), state, weights);
  spdlog::info("depth model: Depth Anything V2 {} from {}", encoder, weights.string());
  return std::make_unique<DepthAnythingNet>(std::move(network), kDepthAnything + "-" + encoder);
}

}  // namespace iesrgs::priors::depth
