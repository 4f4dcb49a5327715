#pragma once
// Stage 2 of IE-SRGS, internal knowledge: a Mip-Splatting model trained on the low-resolution
// views with multi-view regulation, then SR-splatting: every training view rendered from it at s
// times the resolution with the same field of view (I_image, I_depth).
#include <filesystem>
#include <string>

#include "io/scene.hpp"
#include "io/view_images.hpp"
#include "pipeline/training_stage.hpp"
#include "train/config.hpp"

namespace iesrgs::pipeline {

struct InternalStage {
  StageResult training;
  std::filesystem::path sr_dir;  // <dir>/sr: rgb/<name>.png (I_image), depth/<name>.npy (I_depth)
};

// Trains in <dir> (cached and resumable, see training_stage.hpp) on lr_scene's training views,
// reporting PSNR on a few of its test views, then renders the SR-splatting outputs into <dir>/sr
// unless an earlier run left them for the same model and scale. `train_digest` is
// split_digest(lr_images, Split::Train), which the caller computes once for every stage.
InternalStage run_internal_stage(const Scene& lr_scene, const std::string& train_digest,
                                 ViewImages& lr_images, const train::TrainConfig& config, int scale,
                                 const std::filesystem::path& dir);

// Whether <dir> holds a finished internal model for these settings, which run_internal_stage
// would reuse; reads its record alone.
bool internal_model_current(const Scene& lr_scene, const std::string& train_digest,
                            const train::TrainConfig& config, const std::filesystem::path& dir);

// Whether <dir> holds a finished internal model for these settings and its SR-splatting renders
// at `scale`, so that run_internal_stage would only load them.
bool internal_stage_current(const Scene& lr_scene, const std::string& train_digest,
                            const train::TrainConfig& config, int scale,
                            const std::filesystem::path& dir);

}  // namespace iesrgs::pipeline
