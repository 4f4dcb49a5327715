#pragma once
// A training stage of the pipeline (the internal LR model, the HR fusion model) made cacheable
// and resumable: <dir>/stage.json records the stage's parameters and whether it finished. A
// finished stage with the same parameters is loaded instead of trained again; an unfinished one
// continues from its checkpoint; different parameters start over.
#include <filesystem>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "gs/model.hpp"
#include "train/config.hpp"
#include "train/trainer.hpp"

namespace iesrgs::pipeline {

struct StageResult {
  gs::GaussianModel model;
  double seconds = 0;   // training time, as recorded when the stage finished
  bool cached = false;  // loaded from an earlier run
};

// Trains (or loads) the stage in setup.output_dir and writes its point clouds there. `params`
// identifies the stage's inputs beyond the training config. Throws Interrupted on SIGINT or
// SIGTERM, after the checkpoint is written, saying how to resume.
StageResult run_training_stage(const std::string& name, const nlohmann::json& params,
                               const train::TrainConfig& config, train::TrainerSetup setup,
                               const std::function<gs::GaussianModel()>& initial_model);

// Whether <dir> holds a finished stage for these parameters, which run_training_stage would load
// instead of training.
bool training_stage_current(const std::filesystem::path& dir, const nlohmann::json& params,
                            const train::TrainConfig& config);

}  // namespace iesrgs::pipeline
