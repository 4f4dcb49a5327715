#pragma once
// Stage 3 of IE-SRGS: the HR model optimized at the HR camera resolution against the external
// and internal references with the mask-guided texture loss and the geometric loss
// (loss/fusion.hpp). Baselines are the same stage with other references and weights.
#include <array>
#include <filesystem>
#include <functional>
#include <vector>

#include "loss/fusion.hpp"
#include "pipeline/training_stage.hpp"

namespace iesrgs::pipeline {

// Where one training view's references are on disk; empty paths are references the run lacks.
struct ReferenceFiles {
  std::filesystem::path external_image;      // PNG, E_image (or bicubic / HR supervision)
  std::filesystem::path external_disparity;  // .npy, E_depth
  std::filesystem::path internal_image;      // PNG, I_image
  std::filesystem::path internal_depth;      // .npy, I_depth
};

// Reads the references `weights` uses for one HR camera and derives the internal share (the
// discrepancy mask for Masked guidance). Throws Error naming the file that is missing, corrupt
// or not at the camera's resolution.
loss::FusionTargets load_fusion_targets(const ReferenceFiles& files, const Camera& camera,
                                        const loss::FusionWeights& weights, double threshold);

struct FusionSetup {
  std::vector<Camera> cameras;  // HR training cameras
  std::vector<loss::FusionTargets> targets;
  loss::FusionWeights weights;
  std::vector<train::TrainView> test_views;  // HR, for the periodic PSNR report; may be empty
  std::array<float, 3> background{1, 1, 1};
  double scene_extent = 1;
};

// Trains (or reuses, or resumes) the HR model in `dir`; `params` identifies the references.
StageResult run_fusion_stage(FusionSetup setup, const train::TrainConfig& config,
                             const nlohmann::json& params, const std::filesystem::path& dir,
                             const std::function<gs::GaussianModel()>& initial_model);

}  // namespace iesrgs::pipeline
