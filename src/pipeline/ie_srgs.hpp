#pragma once
// The whole IE-SRGS pipeline on one scene: external knowledge, internal knowledge, fusion
// training of the HR model, then rendering and evaluation of the test views at HR; and the
// baselines and ablation rows of the paper as the same stages with other references and weights.
// Every stage is cached in the output folder, so a rerun skips what is done and resumes what was
// interrupted, and rows share the stages they have in common.
#include <filesystem>
#include <string>
#include <vector>

#include "io/scene.hpp"
#include "loss/fusion.hpp"
#include "pipeline/external_stage.hpp"
#include "pipeline/results.hpp"
#include "train/config.hpp"

namespace iesrgs::pipeline {

// What `iesrgs run`, `internal` and `fuse` run.
enum class StageSelection { All, Internal, Fusion };

struct RunOptions {
  std::filesystem::path scene;
  // downscale: the HR resolution the scene is evaluated at; the LR input is the scene at a
  // `scale` times larger downscale (a bicubic resize, or the capture's own downscaled images). With
  // input_is_lr the scene's images are the LR input themselves, nothing is evaluated and the test
  // views are still rendered at HR.
  SceneOptions scene_options;
  bool input_is_lr = false;
  int scale = 4;
  ExternalOptions external;  // its scale is `scale`
  train::TrainConfig internal_config;
  train::TrainConfig fusion_config;
  loss::FusionWeights weights;  // of the ie-srgs row; the ablation rows switch terms off
  double threshold = -1;        // T; negative: 0.6 for synthetic scenes, 0.9 for real ones
  std::string init = "scene";   // HR model start: "scene" (as 3DGS) or "internal" (its Gaussians)
  std::vector<std::string> rows{"ie-srgs"};
  std::string lpips = "alex";
  int diagnostic_views = 4;
  StageSelection only = StageSelection::All;
  std::filesystem::path output;
};

// Runs the selected stages and writes <output>/results.{json,csv,md} after the rows, keeping the
// rows an earlier run in the folder scored (their result.json) that these settings would reuse
// unchanged.
RunResult run_ie_srgs(const RunOptions& options);

}  // namespace iesrgs::pipeline
