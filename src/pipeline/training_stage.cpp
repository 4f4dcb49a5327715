#include "pipeline/training_stage.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <optional>

#include "core/error.hpp"
#include "core/progress.hpp"
#include "io/atomic_file.hpp"
#include "io/ply.hpp"
#include "pipeline/stage_record.hpp"
#include "train/session.hpp"

namespace iesrgs::pipeline {

namespace {

namespace fs = std::filesystem;

// What a training stage's record must match: its inputs and its whole training config. A record
// that differs only in the reporting fields (train::kReportingFields) is this stage's: they leave
// the model as it is, so it is reused, or resumed reporting as now asked.
nlohmann::json training_stage_identity(const fs::path& dir, const nlohmann::json& params,
                                       const train::TrainConfig& config) {
  const nlohmann::json identity = {{"stage", params}, {"training", train::to_json(config)}};
  const nlohmann::json recorded =
      read_stage_record(dir / "stage.json").value("params", nlohmann::json());
  if (!recorded.is_object() || !recorded.value("training", nlohmann::json()).is_object())
    return identity;
  nlohmann::json same = identity;
  for (const char* key : train::kReportingFields)
    if (recorded["training"].contains(key)) same["training"][key] = recorded["training"][key];
  return same == recorded ? same : identity;
}

// A finished stage whose model was deleted (say, because it was damaged) trains again.
bool model_finished(const fs::path& dir, const nlohmann::json& identity) {
  return stage_finished(dir, identity) && fs::exists(train::model_path(dir));
}

}  // namespace

StageResult run_training_stage(const std::string& name, const nlohmann::json& params,
                               const train::TrainConfig& config, train::TrainerSetup setup,
                               const std::function<gs::GaussianModel()>& initial_model) {
  const fs::path dir = setup.output_dir;
  const nlohmann::json identity = training_stage_identity(dir, params, config);
  // The recorded time of a finished stage whose model is made again from its final checkpoint:
  // the later stages that learnt from the model are keyed on it.
  std::optional<double> finished_seconds;
  if (model_finished(dir, identity)) {
    try {
      gs::GaussianModel model =
          gs::model_from_splat_cloud(read_ply(train::model_path(dir), NonFinite::Refuse));
      fmt::print("{}: reusing the finished model in {}\n", name, dir.string());
      return {std::move(model), stage_seconds(dir), true};
    } catch (const Error& e) {
      // Damaged since it was written: made again from the final checkpoint, or trained again.
      fmt::print("{}: {}; writing it again\n", name, e.what());
      finished_seconds = stage_seconds(dir);
    }
  }
  remove_stale_temporaries(dir);  // a killed run's half-written checkpoint, say
  const fs::path checkpoint = train::checkpoint_path(dir);
  const bool recorded = stage_recorded(dir, identity);
  const bool resumable = recorded && fs::exists(checkpoint);
  // A model of other settings or inputs is replaced; one stopped before its first checkpoint
  // simply starts again.
  if (!recorded && fs::exists(train::model_path(dir)))
    spdlog::warn("{}: its settings or inputs changed; training it again in {}", name, dir.string());
  // An older run's checkpoint would be resumed by the next identical run.
  if (!resumable) train::remove_earlier_run(dir);
  record_stage(dir, identity, false, 0);
  std::optional<train::Trainer> trainer;
  if (resumable) {
    try {
      trainer.emplace(train::Trainer::resumed(config, setup));
      fmt::print("{}: resuming {} from {}\n", name, trainer->resume_point(), checkpoint.string());
    } catch (const Error& e) {
      // A checkpoint this stage cannot continue (damaged, or not its own) would stop every rerun.
      fmt::print("{}: {}; training it again from the start\n", name, e.what());
      train::remove_earlier_run(dir);
    }
  }
  if (!trainer) {
    finished_seconds.reset();  // a new model, trained from the start
    trainer.emplace(config, std::move(setup), initial_model());
  }
  const train::TrainSummary summary = trainer->run();
  if (summary.interrupted)
    throw Interrupted(
        fmt::format("{} stopped at iteration {}; run the same command again to resume", name,
                    summary.iterations));
  train::write_point_clouds(dir, *trainer);
  const double seconds = finished_seconds.value_or(summary.seconds);
  record_stage(dir, identity, true, seconds);
  fmt::print("{}: {} Gaussians after {} ({:.2f} it/s)\n", name, summary.gaussians,
             format_duration(seconds), summary.iterations_per_second);
  return {trainer->model(), seconds, false};
}

bool training_stage_current(const fs::path& dir, const nlohmann::json& params,
                            const train::TrainConfig& config) {
  return model_finished(dir, training_stage_identity(dir, params, config));
}

}  // namespace iesrgs::pipeline
