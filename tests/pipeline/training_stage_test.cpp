#include "pipeline/training_stage.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstring>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "pipeline/stage_record.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"
#include "train/session.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::TempDir;

struct StageRun {
  train::TrainConfig config;
  train::TrainerSetup setup;
  Scene scene;
};

StageRun tiny_stage(const std::filesystem::path& dataset, const std::filesystem::path& out) {
  synth::write_synth_dataset(dataset, {synth::SynthFormat::Blender, 16, 4, 1});
  StageRun run{train::make_preset("fast", 3), {}, load_scene(dataset)};
  run.config.checkpoint_every = 0;
  run.config.test_every = 0;
  run.config.init = "random";
  run.config.random_points = 200;
  ViewImages images(run.scene);
  run.setup.train_views = train::load_views(run.scene, Split::Train, images);
  run.setup.background = run.scene.background;
  run.setup.scene_extent = run.scene.normalization().radius;
  run.setup.output_dir = out;
  return run;
}

// A run with new settings that dies before its first checkpoint must not leave the previous
// settings' checkpoint for the next identical run to resume from.
TEST(TrainingStage, NewSettingsNeverResumeAnOlderSettingsCheckpoint) {
  TempDir dir;
  const StageRun run = tiny_stage(dir / "scene", dir / "stage");
  std::filesystem::create_directories(dir / "stage");
  record_stage(dir / "stage", {{"old", "settings"}}, false, 0);
  write_file_atomically(dir / "stage" / "checkpoint.pt", "older settings' checkpoint");

  const auto killed_before_checkpoint = []() -> gs::GaussianModel {
    throw std::runtime_error("killed");
  };
  EXPECT_THROW(run_training_stage("stage", {}, run.config, run.setup, killed_before_checkpoint),
               std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(dir / "stage" / "checkpoint.pt"));

  const auto start = [&] { return train::initial_model(run.scene, run.config, {}); };
  const StageResult result = run_training_stage("stage", {}, run.config, run.setup, start);
  EXPECT_GT(result.model.size(), 0);
  EXPECT_TRUE(training_stage_current(dir / "stage", {}, run.config));
}

// Rerun after Ctrl-C, a stage continues from its checkpoint and builds no starting model.
TEST(TrainingStage, InterruptedStageResumesFromItsCheckpoint) {
  TempDir dir;
  StageRun run = tiny_stage(dir / "scene", dir / "stage");
  run.config.iterations = 12;
  run.config.views_per_iteration = 1;
  int steps = 0;
  run.setup.loss = [&](int view, const raster::RenderOutput& render) {
    if (++steps == 5) std::raise(SIGINT);  // checkpoints after iteration 5 and stops
    return (render.image - run.setup.train_views[size_t(view)].target).abs().mean();
  };
  const auto start = [&] { return train::initial_model(run.scene, run.config, {}); };
  try {
    run_training_stage("stage", {}, run.config, run.setup, start);
    ADD_FAILURE() << "the stage ran to its end";
  } catch (const Interrupted& e) {  // which the CLI turns into exit status 130
    EXPECT_TRUE(testing::contains(e.what(), "stopped at iteration 5")) << e.what();
  }

  const auto no_new_start = []() -> gs::GaussianModel { throw std::runtime_error("drawn"); };
  const StageResult resumed = run_training_stage("stage", {}, run.config, run.setup, no_new_start);
  EXPECT_EQ(steps, 12);
  EXPECT_FALSE(resumed.cached);
  EXPECT_TRUE(training_stage_current(dir / "stage", {}, run.config));
}

// A checkpoint the stage cannot continue (here: its cameras.json is gone) is not resumed on every
// rerun in vain: the stage trains again from the start.
TEST(TrainingStage, UnresumableCheckpointTrainsTheStageAgain) {
  TempDir dir;
  StageRun run = tiny_stage(dir / "scene", dir / "stage");
  run.config.iterations = 12;
  int steps = 0;
  run.setup.loss = [&](int view, const raster::RenderOutput& render) {
    if (++steps == 5) std::raise(SIGINT);
    return (render.image - run.setup.train_views[size_t(view)].target).abs().mean();
  };
  const auto start = [&] { return train::initial_model(run.scene, run.config, {}); };
  EXPECT_THROW(run_training_stage("stage", {}, run.config, run.setup, start), Interrupted);
  std::filesystem::remove(dir / "stage" / "cameras.json");
  int starts = 0;
  const auto counted_start = [&] {
    ++starts;
    return start();
  };
  const StageResult again = run_training_stage("stage", {}, run.config, run.setup, counted_start);
  EXPECT_EQ(starts, 1);
  EXPECT_FALSE(again.cached);
  EXPECT_TRUE(training_stage_current(dir / "stage", {}, run.config));
}

// A finished model damaged since it was written (cut short, or holding a NaN, which training
// never saves and other readers leave out) comes back from the final checkpoint, without training
// and with its recorded time, on which later stages are keyed; with the checkpoint gone too, the
// stage trains again.
TEST(TrainingStage, DamagedFinishedModelIsWrittenAgain) {
  TempDir dir;
  const StageRun run = tiny_stage(dir / "scene", dir / "stage");
  const auto start = [&] { return train::initial_model(run.scene, run.config, {}); };
  const StageResult first = run_training_stage("stage", {}, run.config, run.setup, start);
  const std::filesystem::path ply = dir / "stage" / "point_cloud.ply";
  const std::string intact = read_file(ply);
  std::string not_finite = intact;
  const float nan = std::nanf("");
  std::memcpy(&not_finite[not_finite.find("end_header\n") + 11], &nan, sizeof nan);

  const auto no_new_start = []() -> gs::GaussianModel { throw std::runtime_error("drawn"); };
  for (const std::string& damaged : {intact.substr(0, 300), not_finite}) {
    write_file_atomically(ply, damaged);
    const StageResult restored =
        run_training_stage("stage", {}, run.config, run.setup, no_new_start);
    EXPECT_FALSE(restored.cached);
    EXPECT_EQ(read_file(ply), intact);
    EXPECT_EQ(restored.model.size(), first.model.size());
    EXPECT_EQ(restored.seconds, first.seconds);
    EXPECT_EQ(stage_seconds(dir / "stage"), first.seconds);
  }

  write_file_atomically(ply, intact.substr(0, 300));
  std::filesystem::remove(train::checkpoint_path(dir / "stage"));
  const StageResult again = run_training_stage("stage", {}, run.config, run.setup, start);
  EXPECT_FALSE(again.cached);
  EXPECT_TRUE(training_stage_current(dir / "stage", {}, run.config));
}

}  // namespace
}  // namespace iesrgs::pipeline
