#include "train/config.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <utility>

#include "support/expect_error.hpp"

namespace iesrgs::train {
namespace {

using testing::error_message;

TEST(TrainConfig, PaperPresetIsMethodSchedule) {
  const TrainConfig c = make_preset("paper");
  EXPECT_EQ(c.iterations, 30000);
  EXPECT_EQ(c.densify_from, 500);
  EXPECT_EQ(c.densify_until, 15000);
  EXPECT_EQ(c.densify_every, 100);
  EXPECT_EQ(c.opacity_reset_every, 3000);
  EXPECT_EQ(c.sh_increase_every, 1000);
  EXPECT_DOUBLE_EQ(c.grad_threshold, 2e-4);
  EXPECT_EQ(c.learning_rates.position_max_steps, 30000);
  EXPECT_EQ(c.max_screen_size, 0);  // dead in 3DGS (see config.hpp)
  EXPECT_EQ(c.max_world_size, 0.1);
}

TEST(TrainConfig, ShorterRunsScaleTheScheduleTogether) {
  const TrainConfig c = make_preset("paper", 6000);
  EXPECT_EQ(c.iterations, 6000);
  EXPECT_EQ(c.densify_from, 100);
  EXPECT_EQ(c.densify_until, 3000);
  EXPECT_EQ(c.opacity_reset_every, 600);
  EXPECT_EQ(c.sh_increase_every, 200);
  EXPECT_EQ(c.learning_rates.position_max_steps, 6000);
  EXPECT_EQ(c.densify_every, 100);  // the rhythm of densification stays
  EXPECT_EQ(make_preset("cpu").iterations, 10000);
  EXPECT_EQ(make_preset("fast").iterations, 3000);
  // Short presets prune no large splats (see make_preset); --iterations alone keeps 3DGS's rule.
  EXPECT_EQ(make_preset("cpu").max_world_size, 0);
  EXPECT_EQ(make_preset("fast", 500).max_world_size, 0);
  EXPECT_EQ(c.max_world_size, 0.1);
}

// Pro rata, `fast` at 500 iterations would reset opacities every 50, twice per densification step.
TEST(TrainConfig, OpacityResetsAreNoMoreFrequentThanDensification) {
  EXPECT_EQ(make_preset("fast", 500).opacity_reset_every, 100);
  EXPECT_EQ(make_preset("fast", 1500).opacity_reset_every, 150);
}

// Every field under its own name, each with a value no other field and no default has: a field
// left out of the JSON form, or read into another, shows here. The form is the training stage's
// cache identity, so either would let a changed setting reuse a stale model.
TEST(TrainConfig, JsonRoundTripsEveryField) {
  const nlohmann::json every_field = {{"preset", "cpu"},
                                      {"iterations", 1234},
                                      {"views_per_iteration", 3},
                                      {"seed", 77u},
                                      {"dssim_weight", 0.25},
                                      {"max_sh_degree", 2},
                                      {"sh_increase_every", 101},
                                      {"densify_from", 102},
                                      {"densify_until", 1003},
                                      {"densify_every", 103},
                                      {"opacity_reset_every", 1004},
                                      {"grad_threshold", 3e-4},
                                      {"absolute_gradients", true},
                                      {"percent_dense", 0.02},
                                      {"min_opacity", 0.006},
                                      {"max_screen_size", 21.0},
                                      {"max_world_size", 0.2},
                                      {"filter_update_every", 104},
                                      {"max_gaussians", 5000},
                                      {"lr_position_initial", 1.5e-4},
                                      {"lr_position_final", 1.5e-6},
                                      {"lr_position_max_steps", 1005},
                                      {"lr_sh_dc", 0.125},
                                      {"lr_sh_rest", 0.0625},
                                      {"lr_opacity", 0.0375},
                                      {"lr_scaling", 0.0075},
                                      {"lr_rotation", 0.0015},
                                      {"init", "random"},
                                      {"random_points", 999},
                                      {"random_extent", 1.5},
                                      {"checkpoint_every", 105},
                                      {"test_every", 106},
                                      {"test_views", 7},
                                      {"log_every", 11}};
  TrainConfig c;
  apply_json(c, every_field, "test");
  EXPECT_EQ(c.preset, "cpu");
  EXPECT_EQ(c.iterations, 1234);
  EXPECT_EQ(c.views_per_iteration, 3);
  EXPECT_EQ(c.seed, 77u);
  EXPECT_EQ(c.dssim_weight, 0.25);
  EXPECT_EQ(c.max_sh_degree, 2);
  EXPECT_EQ(c.sh_increase_every, 101);
  EXPECT_EQ(c.densify_from, 102);
  EXPECT_EQ(c.densify_until, 1003);
  EXPECT_EQ(c.densify_every, 103);
  EXPECT_EQ(c.opacity_reset_every, 1004);
  EXPECT_EQ(c.grad_threshold, 3e-4);
  EXPECT_TRUE(c.absolute_gradients);
  EXPECT_EQ(c.percent_dense, 0.02);
  EXPECT_EQ(c.min_opacity, 0.006);
  EXPECT_EQ(c.max_screen_size, 21.0f);
  EXPECT_EQ(c.max_world_size, 0.2);
  EXPECT_EQ(c.filter_update_every, 104);
  EXPECT_EQ(c.max_gaussians, 5000);
  EXPECT_EQ(c.learning_rates.position_initial, 1.5e-4);
  EXPECT_EQ(c.learning_rates.position_final, 1.5e-6);
  EXPECT_EQ(c.learning_rates.position_max_steps, 1005);
  EXPECT_EQ(c.learning_rates.sh_dc, 0.125);
  EXPECT_EQ(c.learning_rates.sh_rest, 0.0625);
  EXPECT_EQ(c.learning_rates.opacity, 0.0375);
  EXPECT_EQ(c.learning_rates.scaling, 0.0075);
  EXPECT_EQ(c.learning_rates.rotation, 0.0015);
  EXPECT_EQ(c.init, "random");
  EXPECT_EQ(c.random_points, 999);
  EXPECT_EQ(c.random_extent, 1.5f);
  EXPECT_EQ(c.checkpoint_every, 105);
  EXPECT_EQ(c.test_every, 106);
  EXPECT_EQ(c.test_views, 7);
  EXPECT_EQ(c.log_every, 11);
  EXPECT_EQ(to_json(c), every_field);  // no field more, none less, written as read
}

// What --resume and a cached stage compare: what the training learns, not how it reports.
TEST(TrainConfig, ChangesLeaveOutHowATrainingReports) {
  const TrainConfig run = make_preset("fast");
  TrainConfig other = run;
  other.checkpoint_every = 7;
  other.test_every = 7;
  other.test_views = 7;
  other.log_every = 7;
  EXPECT_TRUE(config_changes(run, other).empty());
  other.seed = 3;
  EXPECT_EQ(config_changes(run, other), std::vector<std::string>{"seed 3 instead of 0"});
}

TEST(TrainConfig, AssignmentsParseValues) {
  TrainConfig c;
  apply_assignment(c, "grad_threshold=0.0003");
  apply_assignment(c, "absolute_gradients=true");
  apply_assignment(c, "init=random");
  EXPECT_DOUBLE_EQ(c.grad_threshold, 3e-4);
  EXPECT_TRUE(c.absolute_gradients);
  EXPECT_EQ(c.init, "random");
}

TEST(TrainConfig, BadInputNamesTheProblem) {
  TrainConfig c;
  EXPECT_NE(error_message([&] { apply_assignment(c, "grad_treshold=1"); }).find("grad_treshold"),
            std::string::npos);
  EXPECT_NE(error_message([&] { apply_assignment(c, "iterations=lots"); }).find("wrong type"),
            std::string::npos);
  EXPECT_NE(error_message([&] { apply_assignment(c, "novalue"); }).find("key=value"),
            std::string::npos);
  // 200 more than 2^32 would wrap around to 200 in the int field.
  EXPECT_NE(error_message([&] {
              apply_assignment(c, "random_points=4294967496");
            }).find("\"random_points\" is out of range (4294967496)"),
            std::string::npos);
  // Beyond a float, the field would hold an infinity that config.json stores as null.
  EXPECT_NE(error_message([&] {
              apply_assignment(c, "max_screen_size=1e39");
            }).find("\"max_screen_size\" is out of range (1e+39)"),
            std::string::npos);
  // The preset is a record of where the schedule came from, set with --preset.
  EXPECT_NE(error_message([&] { apply_assignment(c, "preset=paper"); }).find("--preset"),
            std::string::npos);
  // The HR and LR stages of `run` take their overrides from two options; errors name the one used.
  EXPECT_NE(error_message([&] {
              apply_assignment(c, "bogus=1", "--internal-");
            }).find("--internal-set bogus=1: unknown training parameter \"bogus\""),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              apply_assignment(c, "preset=paper", "--internal-");
            }).find("chosen with --internal-preset"),
            std::string::npos);
  EXPECT_NE(error_message([] { make_preset("turbo"); }).find("turbo"), std::string::npos);
  c.views_per_iteration = 0;
  EXPECT_NE(error_message([&] { validate(c); }).find("views_per_iteration"), std::string::npos);
}

TEST(TrainConfig, OutOfRangeValuesNameTheParameter) {
  const std::pair<const char*, const char*> cases[] = {
      {"percent_dense=-1", "percent_dense"},     {"min_opacity=1.5", "min_opacity"},
      {"max_world_size=-0.1", "max_world_size"}, {"densify_until=-5", "densify_until"},
      {"lr_scaling=-0.1", "learning rates"},     {"lr_position_final=0", "lr_position_final"}};
  for (const auto& [assignment, named] : cases) {
    TrainConfig c;
    validate(c);
    apply_assignment(c, assignment);
    EXPECT_NE(error_message([&] { validate(c); }).find(named), std::string::npos) << assignment;
  }
  TrainConfig fixed_positions;
  apply_assignment(fixed_positions, "lr_position_initial=0");
  apply_assignment(fixed_positions, "lr_position_final=0");
  validate(fixed_positions);
}

}  // namespace
}  // namespace iesrgs::train
