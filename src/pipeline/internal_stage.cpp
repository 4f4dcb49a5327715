#include "pipeline/internal_stage.hpp"

#include <fmt/core.h>

#include "core/stopwatch.hpp"
#include "pipeline/render_views.hpp"
#include "pipeline/stage_record.hpp"
#include "train/session.hpp"

namespace iesrgs::pipeline {

namespace {

nlohmann::json internal_params(const Scene& lr_scene, const std::string& train_digest) {
  return {{"points", points_digest(lr_scene.points)},
          {"downscale", lr_scene.downscale},
          {"cameras", train_digest}};
}

// A finished training's recorded time tells which model the renders came from.
nlohmann::json sr_params(double model_seconds, int scale) {
  return {{"model_seconds", model_seconds}, {"scale", scale}};
}

// Whether SR-splatting's renders of every training view are there and intact: one deleted or
// damaged renders them again.
bool renders_present(const std::filesystem::path& sr_dir, const Scene& lr_scene, int scale) {
  for (const Camera* camera : lr_scene.split(Split::Train)) {
    const Intrinsics rendered = camera->intrinsics.scaled(scale);
    const RenderedViewFiles files = rendered_view_files(sr_dir, camera->name);
    if (!cached_view_intact(files.rgb, files.depth_npy, rendered.width, rendered.height))
      return false;
  }
  return true;
}

}  // namespace

InternalStage run_internal_stage(const Scene& lr_scene, const std::string& train_digest,
                                 ViewImages& lr_images, const train::TrainConfig& config, int scale,
                                 const std::filesystem::path& dir) {
  train::TrainerSetup setup =
      train::scene_setup(lr_scene, lr_images, size_t(config.test_views), dir);
  const train::TrainConfig& c = config;
  fmt::print("internal model: {} LR views ({}x{}), K = {}, {} iterations\n",
             setup.train_views.size(), setup.train_views.front().camera.intrinsics.width,
             setup.train_views.front().camera.intrinsics.height, setup.views_per_step(c),
             c.iterations);
  std::vector<Camera> cameras;
  for (const train::TrainView& view : setup.train_views) cameras.push_back(view.camera);

  InternalStage stage{
      run_training_stage("internal model", internal_params(lr_scene, train_digest), config,
                         std::move(setup),
                         [&] { return train::initial_model(lr_scene, config, {}); }),
      dir / "sr"};
  const nlohmann::json sr = sr_params(stage.training.seconds, scale);
  if (stage.training.cached && stage_finished(stage.sr_dir, sr) &&
      renders_present(stage.sr_dir, lr_scene, scale))
    return stage;
  fmt::print("SR-splatting: rendering {} training views at x{}\n", cameras.size(), scale);
  const Stopwatch watch;
  render_views_to(stage.sr_dir, stage.training.model, cameras, lr_scene.background, scale);
  record_stage(stage.sr_dir, sr, true, watch.seconds());  // stage_seconds reads it back
  return stage;
}

bool internal_model_current(const Scene& lr_scene, const std::string& train_digest,
                            const train::TrainConfig& config, const std::filesystem::path& dir) {
  return training_stage_current(dir, internal_params(lr_scene, train_digest), config);
}

bool internal_stage_current(const Scene& lr_scene, const std::string& train_digest,
                            const train::TrainConfig& config, int scale,
                            const std::filesystem::path& dir) {
  return internal_model_current(lr_scene, train_digest, config, dir) &&
         stage_finished(dir / "sr", sr_params(stage_seconds(dir), scale)) &&
         renders_present(dir / "sr", lr_scene, scale);
}

}  // namespace iesrgs::pipeline
