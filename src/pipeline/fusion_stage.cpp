#include "pipeline/fusion_stage.hpp"

#include <fmt/core.h>

#include <memory>

#include "core/device.hpp"
#include "core/error.hpp"
#include "io/image.hpp"
#include "io/image_tensor.hpp"
#include "io/npy.hpp"
#include "pipeline/stage_record.hpp"

namespace iesrgs::pipeline {

namespace {

namespace fs = std::filesystem;

torch::Tensor read_reference_image(const fs::path& path, const Intrinsics& size) {
  const Image8 image = read_cached_output(path, read_image8);
  if (image.width != size.width || image.height != size.height)
    fail_file(path, fmt::format("is {}x{}, the HR camera is {}x{}", image.width, image.height,
                                size.width, size.height));
  return to_tensor(to_float(image))[0];
}

torch::Tensor read_reference_map(const fs::path& path, const Intrinsics& size) {
  NpyArray array = read_cached_output(path, read_npy);
  if (array.shape != std::vector<size_t>{size_t(size.height), size_t(size.width)})
    fail_file(path, fmt::format("is not a {}x{} (height x width) map", size.height, size.width));
  return torch::from_blob(array.data.data(), {size.height, size.width}, torch::kFloat).clone();
}

}  // namespace

loss::FusionTargets load_fusion_targets(const ReferenceFiles& files, const Camera& camera,
                                        const loss::FusionWeights& weights, double threshold) {
  const Intrinsics& size = camera.intrinsics;
  const bool internal_texture = weights.texture != loss::TextureGuidance::External;
  const bool external_texture = weights.texture != loss::TextureGuidance::Internal;
  const auto need = [&](const fs::path& path, bool used, const char* what) {
    if (used && path.empty())
      fail("view {}: the loss needs {}, which this run lacks", camera.name, what);
    return used;
  };
  loss::FusionTargets targets;
  if (need(files.external_image, external_texture, "the external image"))
    targets.external_image = read_reference_image(files.external_image, size);
  if (need(files.internal_image, internal_texture, "the internal image"))
    targets.internal_image = read_reference_image(files.internal_image, size);
  if (need(files.internal_depth, weights.internal_depth > 0, "the internal depth"))
    targets.internal_depth = read_reference_map(files.internal_depth, size);
  if (need(files.external_disparity, weights.external_depth > 0, "the external depth"))
    targets.external_disparity = read_reference_map(files.external_disparity, size);
  targets.internal_share = loss::internal_share(weights.texture, targets.internal_image,
                                                targets.external_image, threshold);
  return targets;
}

StageResult run_fusion_stage(FusionSetup setup, const train::TrainConfig& config,
                             const nlohmann::json& params, const fs::path& dir,
                             const std::function<gs::GaussianModel()>& initial_model) {
  train::TrainerSetup trainer_setup;
  for (size_t i = 0; i < setup.cameras.size(); ++i) {
    const loss::FusionTargets& t = setup.targets[i];
    // The trainer's views carry a target; the fusion loss reads its own references instead.
    trainer_setup.train_views.push_back(
        {setup.cameras[i], t.external_image.defined() ? t.external_image : t.internal_image});
  }
  trainer_setup.test_views = std::move(setup.test_views);
  trainer_setup.background = setup.background;
  trainer_setup.scene_extent = setup.scene_extent;
  trainer_setup.output_dir = dir;
  // The loss reads them where the trainer renders.
  auto targets = std::make_shared<std::vector<loss::FusionTargets>>();
  for (const loss::FusionTargets& t : setup.targets) targets->push_back(t.to(compute_device()));
  const loss::FusionWeights weights = setup.weights;
  trainer_setup.loss = [targets, weights](int view, const raster::RenderOutput& render) {
    return loss::fusion_loss(render, (*targets)[size_t(view)], weights).total;
  };
  fmt::print("fusion: {} HR views ({}x{}), texture {}, li {}, le {}, {} iterations\n",
             setup.cameras.size(), setup.cameras.front().intrinsics.width,
             setup.cameras.front().intrinsics.height, loss::texture_guidance_name(weights.texture),
             weights.internal_depth, weights.external_depth, config.iterations);
  return run_training_stage("fusion", params, config, std::move(trainer_setup), initial_model);
}

}  // namespace iesrgs::pipeline
