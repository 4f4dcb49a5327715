// The IE-SRGS pipeline through the binary on a tiny synthetic scene: every stage and row runs,
// results and diagnostics are written, a rerun reuses the cached stages, and misuse is reported.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "support/cli_run.hpp"
#include "support/scoped_env.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::CliRun;
using testing::contains;
using testing::iesrgs;
using testing::last_line;
using testing::ScopedEnv;
using testing::TempDir;

// Edits a PNG: every value inverted.
void invert(const std::filesystem::path& png) {
  Image8 image = read_image8(png);
  for (uint8_t& value : image.data) value = uint8_t(255 - value);
  write_png(png, image);
}

// Short schedules and few Gaussians: this checks the plumbing, not the quality.
constexpr const char* kTinySchedule =
    " --sr-model bicubic --iterations 20 --internal-iterations 20 --set random_points=1500"
    " --internal-set random_points=1500 --diagnostic-views 2 --lpips none";

// Each test's folder: the synthetic scene in `scene`, the run in `out`.
class RunCli : public ::testing::Test {
 protected:
  // Writes the scene (seed 3); returns the exit status of synth.
  int write_scene(int size, int views, int test_views) {
    return iesrgs("synth -o " + scene + " --size " + std::to_string(size) + " --views " +
                  std::to_string(views) + " --test-views " + std::to_string(test_views) +
                  " --seed 3")
        .status;
  }

  // `iesrgs run` of the scene into the run folder on the short schedule: `rows`, then `extra`.
  CliRun run_rows(const std::string& rows, const std::string& extra = "") const {
    return iesrgs("run " + scene + " -o " + out + " --rows " + rows + extra + kTinySchedule);
  }

  TempDir dir;
  const std::string scene = (dir / "scene").string(), out = (dir / "run").string();
};

TEST_F(RunCli, SaysOnceWhyLpipsIsMissing) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  const ScopedEnv torch_home("TORCH_HOME", (dir / "empty-torch-cache").string());
  const ScopedEnv no_weights("IESRGS_WEIGHTS_DIR", std::nullopt);
  std::string schedule = kTinySchedule;
  schedule.replace(schedule.find("--lpips none"), 12, "--lpips alex");
  const CliRun run = iesrgs("run " + scene + " -o " + out + " --rows bicubic,external" + schedule);
  ASSERT_EQ(run.status, 0) << run.output;
  const size_t said = run.output.find("LPIPS (alex) unavailable: ");
  EXPECT_NE(said, std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("LPIPS (alex) unavailable", said + 1), std::string::npos) << run.output;
  // Before any training: the first row's progress comes after it.
  EXPECT_LT(said, run.output.find("it/s")) << run.output;
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  EXPECT_EQ(results["evaluation"]["lpips"], "alex") << results.dump();
  EXPECT_EQ(results["evaluation"]["lpips_status"].get<std::string>().rfind("unavailable: ", 0), 0u)
      << results.dump();
}

TEST_F(RunCli, RunsEveryStageAndRowThenReusesThem) {
  ASSERT_EQ(write_scene(48, 6, 2), 0);
  const std::string command =
      "run " + scene + " -o " + out + " --rows demo,hr,joint,mask-oracle" + kTinySchedule;
  const CliRun first = iesrgs(command);
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_TRUE(contains(first.output, "IE-SRGS (+ mask)")) << first.output;
  // Seven rows, six of them trained at HR: where the run stands after each but the last.
  EXPECT_TRUE(contains(first.output, "== row 7/7 hr: ")) << first.output;
  EXPECT_TRUE(contains(first.output, "HR rows: 5 of 6 done in ")) << first.output;
  EXPECT_TRUE(contains(first.output, "for the rest")) << first.output;
  EXPECT_FALSE(contains(first.output, "HR rows: 6 of 6")) << first.output;

  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  ASSERT_EQ(results["rows"].size(), 7u);
  for (const auto& row : results["rows"]) {
    EXPECT_GT(row["psnr"].get<double>(), 8.0) << row.dump();
    EXPECT_GT(row["fps"].get<double>(), 0.0) << row.dump();
  }
  EXPECT_EQ(results["rows"][0]["row"], "bicubic");
  EXPECT_EQ(results["rows"][5]["row"], "mask-oracle");
  EXPECT_EQ(results["rows"][6]["row"], "hr");
  EXPECT_TRUE(results["stages"].contains("internal_training_seconds"));
  const std::string markdown = read_file(dir / "run" / "results.md");
  for (const char* stage : {"| internal model (LR Mip-Splatting) | ", "| HR training, ie-srgs | ",
                            "| rendering and scoring, internal | ", "| this run in all | "})
    EXPECT_TRUE(contains(markdown, stage)) << markdown;
  for (const char* file :
       {"results.csv", "results.md", "external/image/r_0.png", "bicubic/image/r_0.png",
        "internal/point_cloud.ply", "internal/sr/rgb/r_0.png", "internal/sr/depth/r_0.npy",
        "rows/ie-srgs/point_cloud.ply", "rows/ie-srgs/test/metrics.json",
        "diagnostics/contact_sheet.png", "diagnostics/contact_sheet.html",
        "diagnostics/r_0/mask.png", "diagnostics/r_0/mask_check.png", "diagnostics/r_0/truth.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "run" / file)) << file;
  const auto agreement =
      nlohmann::json::parse(read_file(dir / "run" / "diagnostics/mask_agreement.json"));
  EXPECT_EQ(agreement["views"], 6);
  for (const char* key :
       {"mask_share", "truth_mask_share", "iou", "internal_closer_share", "oracle_mask_share"})
    EXPECT_TRUE(agreement[key].get<double>() >= 0 && agreement[key].get<double>() <= 1) << key;
  for (const char* key : {"psnr_external", "psnr_internal", "psnr_fused", "psnr_oracle"})
    EXPECT_GT(agreement[key].get<double>(), 8.0) << key;
  // Recorded as iesrgs render records its views, for eval to score them as the run did.
  const auto record =
      nlohmann::json::parse(read_file(dir / "run" / "rows/ie-srgs/test/render.json"));
  EXPECT_EQ(record["split"], "test");
  EXPECT_EQ(record["finished"], true);
  EXPECT_EQ(record["background"], nlohmann::json::array({1, 1, 1}));
  const ImageHeader render = read_image_header(dir / "run" / "rows/ie-srgs/test/rgb/r_0.png");
  EXPECT_EQ(render.width, 48);
  EXPECT_EQ(read_image_header(dir / "run" / "internal/sr/rgb/r_0.png").width, 48);

  const CliRun info = iesrgs("info " + out);
  ASSERT_EQ(info.status, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "| IE-SRGS (+ mask) |")) << info.output;
  EXPECT_TRUE(contains(info.output, "rows/hr/point_cloud.ply")) << info.output;

  const CliRun second = iesrgs(command);
  ASSERT_EQ(second.status, 0) << second.output;
  EXPECT_TRUE(contains(second.output, "reusing the finished model")) << second.output;
  EXPECT_FALSE(contains(second.output, "settings or inputs changed")) << second.output;
  // The cached stages count the time they took when they ran, the external ones too.
  const auto reused = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  EXPECT_GT(results["stages"]["external_seconds"].get<double>(), 0.0);
  for (const char* stage : {"external_seconds", "internal_training_seconds"})
    EXPECT_EQ(reused["stages"][stage], results["stages"][stage]) << stage;
  EXPECT_FALSE(contains(second.output, "it/s |")) << second.output;
  // No row trained, so no pace to give an ETA by.
  EXPECT_TRUE(contains(second.output, "HR rows: 5 of 6 done in ")) << second.output;
  EXPECT_FALSE(contains(second.output, "for the rest")) << second.output;

  // Rerunning one row keeps the rest of the folder's table.
  using Table = std::vector<std::pair<std::string, bool>>;
  const std::string external_args = scene + " -o " + out + " --rows external" + kTinySchedule;
  const std::string external_only = "run " + external_args;
  const CliRun one = iesrgs(external_only);
  ASSERT_EQ(one.status, 0) << one.output;
  EXPECT_FALSE(contains(one.output, "it/s |")) << one.output;
  const auto table = [&] {
    const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
    Table rows;  // in table order: row, kept from an earlier run
    for (const auto& row : results["rows"])
      rows.emplace_back(row["row"], row.value("from_earlier_run", false));
    return rows;
  };
  const Table kept = {{"bicubic", true}, {"internal", true}, {"external", false},
                      {"joint", true},   {"ie-srgs", true},  {"mask-oracle", true},
                      {"hr", true}};
  EXPECT_EQ(table(), kept);
  EXPECT_TRUE(contains(read_file(dir / "run" / "results.md"), "from an earlier run"));

  // Another internal model: the rows built on it leave the table, the others stay (fuse too).
  const CliRun other = iesrgs("-v fuse " + external_args + " --internal-set seed=7");
  ASSERT_EQ(other.status, 0) << other.output;
  // With -v, why the stage is made again.
  const std::string why = "internal/stage.json: recorded with other parameters (/training/seed)";
  EXPECT_TRUE(contains(other.output, why)) << other.output;
  EXPECT_EQ(other.output.find(why), other.output.rfind(why)) << other.output;  // said once
  const Table independent = {{"bicubic", true}, {"external", false}, {"hr", true}};
  EXPECT_EQ(table(), independent);

  // A damaged score costs only its row.
  const auto hr_result = dir / "run" / "rows" / "hr" / "result.json";
  auto hr = nlohmann::json::parse(read_file(hr_result));
  hr["row"]["psnr"] = "bad";
  write_file_atomically(hr_result, hr.dump());
  write_file_atomically(dir / "run" / "rows" / "bicubic" / "result.json", "{\"evaluation\": ");
  const CliRun damaged = iesrgs(external_only + " --internal-set seed=7");
  ASSERT_EQ(damaged.status, 0) << damaged.output;
  EXPECT_EQ(table(), (Table{{"external", false}}));
}

TEST_F(RunCli, FuseAloneNeedsTheEarlierStagesAndRowsAreChecked) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  const CliRun fuse =
      iesrgs("fuse " + scene + " -o " + out + " --background 0.5,0.5,0.5" + kTinySchedule);
  EXPECT_EQ(fuse.status, 1);
  EXPECT_TRUE(contains(last_line(fuse.output), "external: the external stage here is missing"))
      << fuse.output;
  // The hint is a command that makes the stage this run wants: its scene, scale and options.
  EXPECT_TRUE(contains(fuse.output, "iesrgs external " + scene +
                                        " --downscale 4 --scale 4 --sr-model bicubic --background "
                                        "0.5,0.5,0.5 -o " +
                                        out + "/external or iesrgs run"))
      << fuse.output;
  EXPECT_FALSE(std::filesystem::exists(out));  // refused: no empty run folder left behind

  const CliRun rows = iesrgs("run " + scene + " -o " + out + " --rows best" + kTinySchedule);
  EXPECT_EQ(rows.status, 1);
  EXPECT_TRUE(contains(last_line(rows.output), "unknown row 'best'")) << rows.output;

  const CliRun thirds =
      iesrgs("run " + scene + " -o " + out + " --scale 3 --rows mask-oracle" + kTinySchedule);
  EXPECT_EQ(thirds.status, 1);
  EXPECT_TRUE(contains(last_line(thirds.output), "32x32, which --scale 3 does not divide"))
      << thirds.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The other rows take such a scale, and say what it does to the sizes.
  const CliRun rounded =
      iesrgs("run " + scene + " -o " + out + " --scale 3 --rows bicubic" + kTinySchedule);
  EXPECT_EQ(rounded.status, 0) << rounded.output;
  EXPECT_TRUE(contains(rounded.output,
                       "32x32, which --scale 3 does not divide: its LR view is 11x11 (rounded), so "
                       "the HR models train at 33x33 and are scored at 32x32"))
      << rounded.output;
  std::filesystem::remove_all(out);

  const CliRun dssim = iesrgs("run " + scene + " -o " + out + " --dssim nan");
  EXPECT_NE(dssim.status, 0);
  EXPECT_TRUE(contains(dssim.output, "must be a number in [0, 1], got nan")) << dssim.output;

  const CliRun unused = iesrgs("run " + scene + " -o " + out + " --set dssim_weight=0.5");
  EXPECT_EQ(unused.status, 1);
  EXPECT_TRUE(contains(last_line(unused.output), "takes its D-SSIM weight from --dssim"))
      << unused.output;

  const CliRun twice = iesrgs("run " + scene + " -o " + out +
                              " --internal-mv 2 --internal-set views_per_iteration=3");
  EXPECT_EQ(twice.status, 1);
  EXPECT_TRUE(contains(last_line(twice.output),
                       "--internal-mv and --internal-set views_per_iteration=3 both set "
                       "views_per_iteration"))
      << twice.output;
  EXPECT_EQ(iesrgs("run " + scene + " -o " + out + " --seed 1 --set seed=2").status, 1);

  const CliRun seed = iesrgs("run " + scene + " -o " + out + " --seed -5");
  EXPECT_NE(seed.status, 0);
  EXPECT_TRUE(contains(seed.output, "--seed: must be at least 0, got -5")) << seed.output;

  const CliRun threshold = iesrgs("run " + scene + " -o " + out + " --threshold -0.5");
  EXPECT_NE(threshold.status, 0);
  EXPECT_TRUE(contains(threshold.output, "--threshold: must be at least 0, got -0.5"))
      << threshold.output;

  const CliRun internal = iesrgs("internal " + scene + " -o " + out + kTinySchedule);
  ASSERT_EQ(internal.status, 0) << internal.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "run" / "internal/sr/rgb/r_0.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "run" / "results.json"));
  const CliRun info = iesrgs("info " + out);  // a run folder already, of the internal model
  EXPECT_TRUE(contains(info.output, "no results.md yet")) << info.output;
  EXPECT_TRUE(contains(info.output, "model of internal")) << info.output;

  // fuse trains the HR rows alone: an internal model of other settings is refused, not retrained.
  const std::string other_schedule =
      " --sr-model bicubic --internal-iterations 21 --internal-set random_points=1500 --lpips none";
  const CliRun stale = iesrgs("fuse " + scene + " -o " + out + " --rows internal" + other_schedule);
  EXPECT_EQ(stale.status, 1);
  EXPECT_TRUE(contains(last_line(stale.output), "internal: the internal stage here is missing"))
      << stale.output;
  EXPECT_FALSE(contains(stale.output, "it/s |")) << stale.output;
  const CliRun current =
      iesrgs("fuse " + scene + " -o " + out + " --rows internal" + kTinySchedule);
  ASSERT_EQ(current.status, 0) << current.output;
  EXPECT_TRUE(contains(current.output, "internal only")) << current.output;
}

// The SR network loads only once the stage has found a view to compute, after the output folder
// was taken.
TEST_F(RunCli, AMissingCheckpointLeavesNoOutputFolder) {
  ASSERT_EQ(write_scene(16, 3, 1), 0);
  for (const std::string command : {"run", "external"}) {
    const CliRun refused =
        iesrgs(command + " " + scene + " -o " + out + "/nested --sr-model swinir");
    EXPECT_EQ(refused.status, 1) << command;
    EXPECT_TRUE(contains(last_line(refused.output), "swinir: no checkpoint file given"))
        << refused.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << command;
  }
}

// A rerun stopped partway leaves no table or test renders of the earlier run that read as its
// own, and a row trained again under other settings says so.
TEST_F(RunCli, AStoppedRerunLeavesNothingOfTheEarlierRunThatReadsAsItsOwn) {
  ASSERT_EQ(write_scene(16, 3, 1), 0);
  ASSERT_EQ(run_rows("internal,external").status, 0);
  const std::filesystem::path run = dir / "run";
  const CliRun info = iesrgs("info " + out);
  EXPECT_TRUE(contains(info.output, "| external only")) << info.output;
  EXPECT_TRUE(contains(info.output, "model of internal")) << info.output;
  EXPECT_TRUE(contains(info.output, "rows/external/point_cloud.ply")) << info.output;
  // Where one model is wanted, a run folder is named as such.
  const CliRun whole = iesrgs("export " + out + " " + (dir / "x.spz").string());
  EXPECT_EQ(whole.status, 1);
  EXPECT_TRUE(contains(last_line(whole.output), "a run folder of iesrgs run")) << whole.output;
  const auto finished = [&](const char* row) {
    const auto record =
        nlohmann::json::parse(read_file(run / "rows" / row / "test" / "render.json"));
    return record["finished"].get<bool>();
  };
  ASSERT_TRUE(finished("external"));

  // Stopped in the external stage, which has no checkpoint for the network asked for.
  const CliRun stopped = iesrgs("run " + scene + " -o " + out +
                                " --rows internal,external --sr-model swinir --lpips none");
  ASSERT_EQ(stopped.status, 1) << stopped.output;
  EXPECT_FALSE(std::filesystem::exists(run / "results.md"));
  EXPECT_FALSE(std::filesystem::exists(run / "results.csv"));
  EXPECT_FALSE(std::filesystem::exists(run / "results.json"));
  for (const char* row : {"internal", "external"}) {
    EXPECT_FALSE(finished(row)) << row;
    EXPECT_FALSE(std::filesystem::exists(run / "rows" / row / "result.json")) << row;
    EXPECT_FALSE(std::filesystem::exists(run / "rows" / row / "test" / "metrics.json")) << row;
  }
  EXPECT_TRUE(contains(iesrgs("info " + out).output, "no results.md yet"));
  // The diagnostics, which the ie-srgs row writes again, go too.
  testing::write_text(run / "diagnostics" / "r_9" / "mask.png", "of an earlier run");
  ASSERT_EQ(iesrgs("run " + scene + " -o " + out +
                   " --rows internal,ie-srgs --sr-model swinir --lpips none")
                .status,
            1);
  EXPECT_FALSE(std::filesystem::exists(run / "diagnostics"));

  // The earlier command again writes them back from its cached stages; other settings retrain.
  ASSERT_EQ(run_rows("internal,external").status, 0);
  EXPECT_TRUE(std::filesystem::exists(run / "results.md"));
  EXPECT_TRUE(finished("external"));
  const CliRun reseeded = run_rows("external", " --set seed=4");
  ASSERT_EQ(reseeded.status, 0) << reseeded.output;
  EXPECT_TRUE(
      contains(reseeded.output, "fusion: its settings or inputs changed; training it again"))
      << reseeded.output;
  // A damaged record is rendered over.
  write_file_atomically(run / "rows" / "external" / "test" / "render.json", R"({"finished": 1})");
  const CliRun damaged = run_rows("external", " --set seed=4");
  ASSERT_EQ(damaged.status, 0) << damaged.output;
  EXPECT_FALSE(contains(damaged.output, "settings or inputs changed")) << damaged.output;
  EXPECT_TRUE(finished("external"));
  // How a training reports and checkpoints is not what it learns: the stage is reused.
  const CliRun reporting = run_rows("external", " --set seed=4 --set checkpoint_every=3");
  ASSERT_EQ(reporting.status, 0) << reporting.output;
  EXPECT_TRUE(contains(reporting.output, "fusion: reusing the finished model")) << reporting.output;

  // iesrgs internal leaves the table alone while its model stays, and not once it changes.
  const std::string internal = "internal " + scene + " -o " + out + kTinySchedule;
  ASSERT_EQ(iesrgs(internal).status, 0);
  EXPECT_TRUE(std::filesystem::exists(run / "results.md"));
  EXPECT_TRUE(finished("internal"));
  ASSERT_EQ(iesrgs(internal + " --internal-set seed=7").status, 0);
  EXPECT_FALSE(std::filesystem::exists(run / "results.md"));
  EXPECT_FALSE(finished("internal"));
}

// 50 / 4 rounds up to 13 LR pixels, so the HR training views are 52 wide and the truth 50: the
// diagnostics that compare with the truth are left out, saying why.
TEST_F(RunCli, DiagnosticsSayWhyTheTruthIsLeftOut) {
  ASSERT_EQ(write_scene(50, 3, 1), 0);
  const CliRun run = run_rows("ie-srgs");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "HR truth is 50x50, the HR training view 52x52")) << run.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "run" / "diagnostics" / "contact_sheet.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "run" / "diagnostics" / "mask_agreement.json"));
}

// The ETA is for the rows left to train: after external here, none, since ie-srgs is cached.
TEST_F(RunCli, RowsReusedFromTheCacheAreLeftOutOfTheEta) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("ie-srgs").status, 0);
  const CliRun run = run_rows("external,ie-srgs");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "HR rows: 1 of 2 done in ")) << run.output;
  EXPECT_FALSE(contains(run.output, "for the rest")) << run.output;
}

// Labels say what trained a row when the options changed it: the ie-srgs row off the mask, the
// E_depth row without a depth model (so trained as external only). A run with no mask checks
// none, and the earlier run's check is not left to pass for its own.
TEST_F(RunCli, RowLabelsSayWhatTrainedThem) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("ie-srgs").status, 0);
  const std::filesystem::path agreement = dir / "run" / "diagnostics/mask_agreement.json";
  ASSERT_TRUE(std::filesystem::exists(agreement));
  const CliRun run = run_rows("ie-srgs,external-depth", " --texture external");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "== row 2/2 ie-srgs: IE-SRGS, external texture (no mask) =="))
      << run.output;
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  EXPECT_EQ(results["rows"][0]["label"], "+ E_depth (off: no --depth-model)");
  EXPECT_EQ(results["rows"][1]["label"], "IE-SRGS, external texture (no mask)");
  EXPECT_FALSE(std::filesystem::exists(agreement));
}

TEST_F(RunCli, LowResolutionInputIsRenderedAtHrWithoutMetrics) {
  ASSERT_EQ(write_scene(16, 5, 1), 0);
  // The folder's earlier table, from a benchmark of the same images, has an hr row.
  ASSERT_EQ(run_rows("hr").status, 0);
  const CliRun run = iesrgs("run " + scene + " -o " + out + " --input-is-lr" + kTinySchedule);
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(read_image_header(dir / "run" / "rows/ie-srgs/test/rgb/r_0.png").width, 64);
  EXPECT_FALSE(std::filesystem::exists(dir / "run" / "rows/ie-srgs/test/metrics.json"));
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  ASSERT_EQ(results["rows"].size(), 1u);
  EXPECT_FALSE(results["rows"][0].contains("psnr"));

  for (const char* row : {"hr", "mask-oracle"}) {
    const CliRun needs_truth = run_rows(row, " --input-is-lr");
    EXPECT_EQ(needs_truth.status, 1) << row;
    EXPECT_TRUE(contains(last_line(needs_truth.output), "need HR images")) << needs_truth.output;
  }
}

// Rows that start from the internal model train a copy: the internal-only row, evaluated after
// the bicubic row trained from it, still renders the model as the internal stage left it.
TEST_F(RunCli, RowsStartingFromTheInternalModelLeaveItUnchanged) {
  ASSERT_EQ(write_scene(32, 4, 2), 0);
  const auto internal_psnr = [&] {
    const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
    for (const auto& row : results["rows"])
      if (row["row"] == "internal") return row["psnr"].get<double>();
    ADD_FAILURE() << "no internal row in " << results.dump();
    return 0.0;
  };
  ASSERT_EQ(run_rows("internal").status, 0);
  const double alone = internal_psnr();
  const CliRun after_bicubic = run_rows("bicubic,internal", " --init internal");
  ASSERT_EQ(after_bicubic.status, 0) << after_bicubic.output;
  EXPECT_EQ(internal_psnr(), alone);
}

// A run that trains the internal model again under other settings drops the internal-only row
// that scored the old one.
TEST_F(RunCli, RetrainedInternalModelDropsTheEarlierInternalRow) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("internal,external").status, 0);
  const CliRun retrained = run_rows("joint", " --internal-set seed=7");
  ASSERT_EQ(retrained.status, 0) << retrained.output;
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  std::vector<std::string> ids;
  for (const auto& row : results["rows"]) ids.push_back(row["row"]);
  EXPECT_EQ(ids, (std::vector<std::string>{"external", "joint"}));
}

// An earlier row stays only while its stage holds the model it scored: a run that trained the
// row again and stopped before writing the table leaves the old entry behind.
TEST_F(RunCli, AnEarlierRowIsKeptOnlyForTheModelItScored) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("bicubic,external").status, 0);
  const auto scored_path = dir / "run" / "rows" / "external" / "result.json";
  auto scored = nlohmann::json::parse(read_file(scored_path));
  scored["row"]["train_seconds"] = scored["row"]["train_seconds"].get<double>() + 1;
  write_file_atomically(scored_path, scored.dump());
  ASSERT_EQ(run_rows("bicubic").status, 0);
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  ASSERT_EQ(results["rows"].size(), 1u) << results.dump();
  EXPECT_EQ(results["rows"][0]["row"], "bicubic");
}

// A folder written before rows kept their own scores had them in results.json alone.
TEST_F(RunCli, RowsOfAnOlderFolderAreKeptFromItsTable) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("bicubic,external").status, 0);
  for (const char* row : {"bicubic", "external"})
    std::filesystem::remove(dir / "run" / "rows" / row / "result.json");
  ASSERT_EQ(run_rows("bicubic").status, 0);
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  ASSERT_EQ(results["rows"].size(), 2u) << results.dump();
  EXPECT_EQ(results["rows"][1]["row"], "external");
  EXPECT_TRUE(results["rows"][1]["from_earlier_run"].get<bool>());
}

// A row scored under these settings is kept even when a run under other settings came between:
// the table of that run left it out, its own folder kept its scores.
TEST_F(RunCli, ARowComesBackWithTheSettingsItWasScoredUnder) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("external,ie-srgs", " --threshold 0.3").status, 0);
  const auto rows = [&] {
    const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
    std::vector<std::string> ids;
    for (const auto& row : results["rows"]) ids.push_back(row["row"]);
    return ids;
  };
  ASSERT_EQ(run_rows("external").status, 0);  // T = 0.6: ie-srgs is not this setting's
  EXPECT_EQ(rows(), std::vector<std::string>{"external"});
  const CliRun back = run_rows("external", " --threshold 0.3");
  ASSERT_EQ(back.status, 0) << back.output;
  EXPECT_EQ(rows(), (std::vector<std::string>{"external", "ie-srgs"}));
}

// The oracle mask comes from the HR truth: an edited HR view trains the row again, though the LR
// input, read from pre-downscaled copies, stays the same.
TEST_F(RunCli, AnEditedTruthRetrainsTheOracleRow) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  for (int i = 0; i < 4; ++i) {
    const std::string name = "r_" + std::to_string(i) + ".png";
    const Image8 hr = read_image8(dir / "scene/train" / name);
    Image8 lr(8, 8, hr.channels);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x)
        for (int c = 0; c < hr.channels; ++c)
          lr.data[size_t((y * 8 + x) * hr.channels + c)] =
              hr.data[size_t((4 * y * 32 + 4 * x) * hr.channels + c)];
    write_png(dir / "scene/train_4" / name, lr);
  }
  ASSERT_EQ(run_rows("mask-oracle").status, 0);
  const auto truth = dir / "scene/train/r_1.png";
  invert(truth);
  const CliRun again = run_rows("mask-oracle");
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_TRUE(contains(again.output, "external stage: 0 views computed")) << again.output;
  EXPECT_FALSE(contains(again.output,
                        "reusing the finished model in " + (dir / "run/rows/mask-oracle").string()))
      << again.output;
}

// T shapes the discrepancy mask alone: another T trains the ie-srgs row again, not the others.
TEST_F(RunCli, AnotherThresholdRetrainsOnlyTheMaskedRow) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("external,ie-srgs").status, 0);
  const CliRun again = run_rows("external,ie-srgs", " --threshold 0.3");
  ASSERT_EQ(again.status, 0) << again.output;
  const std::string rows_dir = (dir / "run" / "rows").string();
  EXPECT_TRUE(contains(again.output, "reusing the finished model in " + rows_dir + "/external"))
      << again.output;
  EXPECT_FALSE(contains(again.output, "reusing the finished model in " + rows_dir + "/ie-srgs"))
      << again.output;
}

// With --sr-model auto, a run without super-resolved rows still names the prior its kept rows
// were made with.
TEST_F(RunCli, RowsOfTheAutomaticPriorAreKeptByARunWithoutThem) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  const std::string rows = "run " + scene + " -o " + out +
                           " --iterations 20 --internal-iterations 20 --set random_points=1500"
                           " --internal-set random_points=1500 --lpips none --rows ";
  ASSERT_EQ(iesrgs(rows + "bicubic,external").status, 0);
  const CliRun bicubic = iesrgs(rows + "bicubic");
  ASSERT_EQ(bicubic.status, 0) << bicubic.output;
  EXPECT_FALSE(contains(bicubic.output, "SR prior:")) << bicubic.output;
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  ASSERT_EQ(results["rows"].size(), 2u) << results.dump();
  EXPECT_EQ(results["rows"][1]["row"], "external");
  EXPECT_TRUE(results["rows"][1].value("from_earlier_run", false));
}

// Earlier rows scored against test views that changed since leave the table, the internal-only
// row too, though its model learnt from the unchanged training views.
TEST_F(RunCli, RowsScoredAgainstOtherTestViewsLeaveTheTable) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  ASSERT_EQ(run_rows("internal,bicubic").status, 0);
  const auto test_image = dir / "scene/test/r_0.png";
  invert(test_image);
  const CliRun again = run_rows("bicubic");
  ASSERT_EQ(again.status, 0) << again.output;
  const auto results = nlohmann::json::parse(read_file(dir / "run" / "results.json"));
  ASSERT_EQ(results["rows"].size(), 1u) << results.dump();
  EXPECT_EQ(results["rows"][0]["row"], "bicubic");
}

// Caches follow the images' content, not their folder: rewriting the same bytes (a copied
// dataset) or moving the dataset reuses every stage; an edited training image recomputes its
// E_image, the internal model and the rows, and so does another background.
TEST_F(RunCli, EditedTrainingImageRecomputesWhatLearntFromIt) {
  ASSERT_EQ(write_scene(32, 4, 1), 0);
  const auto command = [&](const std::string& folder, const std::string& extra = "") {
    return "run " + (dir / folder).string() + " -o " + out + " --rows ie-srgs,hr" + kTinySchedule +
           extra;
  };
  ASSERT_EQ(iesrgs(command("scene")).status, 0);
  const auto image = dir / "scene/train/r_1.png";
  write_file_atomically(image, read_file(image));
  std::filesystem::rename(dir / "scene", dir / "moved");
  const CliRun copied = iesrgs(command("moved"));
  ASSERT_EQ(copied.status, 0) << copied.output;
  EXPECT_TRUE(contains(copied.output, "0 views computed, 4 reused")) << copied.output;
  EXPECT_FALSE(contains(copied.output, "it/s |")) << copied.output;

  const auto moved_image = dir / "moved/train/r_1.png";
  invert(moved_image);
  const CliRun changed = iesrgs(command("moved"));
  ASSERT_EQ(changed.status, 0) << changed.output;
  EXPECT_TRUE(contains(changed.output, "1 views computed, 3 reused")) << changed.output;
  EXPECT_FALSE(contains(changed.output, "reusing the finished model")) << changed.output;

  const CliRun black = iesrgs(command("moved", " --background black"));
  ASSERT_EQ(black.status, 0) << black.output;
  EXPECT_TRUE(contains(black.output, "4 views computed, 0 reused")) << black.output;
  EXPECT_FALSE(contains(black.output, "reusing the finished model")) << black.output;
}

}  // namespace
}  // namespace iesrgs
