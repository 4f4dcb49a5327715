// The training workflow through the binary: synth -> train -> render -> eval, and its errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "core/memory.hpp"
#include "io/atomic_file.hpp"
#include "io/folder_lock.hpp"
#include "io/image.hpp"
#include "io/ply.hpp"
#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::CliRun;
using testing::contains;
using testing::iesrgs;
using testing::last_line;
using testing::TempDir;

TEST(TrainCli, TrainRenderEvalWriteStandardOutputs) {
  TempDir dir;
  const std::string scene = (dir / "scene").string(), out = (dir / "run").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 32 --views 6 --test-views 2 --seed 2").status, 0);
  const CliRun train =
      iesrgs("train " + scene + " -o " + out +
             " --preset fast --iterations 30 --mv 2 --seed 4 --set random_points=1500"
             " --set init=random");
  ASSERT_EQ(train.status, 0) << train.output;
  EXPECT_TRUE(contains(train.output, "it/s")) << train.output;
  EXPECT_FALSE(contains(train.output, "replaced the earlier run")) << train.output;
  for (const char* file : {"point_cloud.ply", "point_cloud_filter_baked.ply", "config.json",
                           "training.json", "train_log.csv", "checkpoint.pt", "cameras.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / "run" / file)) << file;
  const auto config = nlohmann::json::parse(read_file(dir / "run" / "config.json"));
  EXPECT_EQ(config["views_per_iteration"], 2);
  EXPECT_EQ(config["iterations"], 30);

  const std::string renders = (dir / "renders").string();
  const CliRun render = iesrgs("render " + out + " " + scene + " -o " + renders + " --scale 2");
  ASSERT_EQ(render.status, 0) << render.output;
  const ImageHeader rgb = read_image_header(dir / "renders" / "rgb" / "r_0.png");
  EXPECT_EQ(rgb.width, 64);
  EXPECT_TRUE(std::filesystem::exists(dir / "renders" / "depth" / "r_0.npy"));
  EXPECT_TRUE(std::filesystem::exists(dir / "renders" / "depth" / "r_0.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "renders" / "alpha" / "r_0.png"));

  const std::string same_size = (dir / "same").string();
  ASSERT_EQ(iesrgs("render " + out + " " + scene + " -o " + same_size).status, 0);
  const CliRun eval = iesrgs("eval " + same_size + " " + scene);
  ASSERT_EQ(eval.status, 0) << eval.output;
  const auto metrics = nlohmann::json::parse(read_file(dir / "same" / "metrics.json"));
  EXPECT_EQ(metrics["views"].size(), 2u);
  EXPECT_GT(metrics["mean"]["psnr"].get<double>(), 10.0);
  EXPECT_TRUE(std::filesystem::exists(dir / "same" / "metrics.csv"));
  // Rendered again, the folder's scores of the earlier renders go with them.
  ASSERT_EQ(iesrgs("render " + out + " " + scene + " -o " + same_size).status, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "same" / "metrics.json"));
  EXPECT_FALSE(std::filesystem::exists(dir / "same" / "metrics.csv"));
  ASSERT_EQ(iesrgs("eval " + same_size + " " + scene).status, 0);
  // A report path naming its .json names the pair.
  ASSERT_EQ(iesrgs("eval --lpips none " + same_size + " " + scene + " -o " +
                   (dir / "report.json").string())
                .status,
            0);
  EXPECT_TRUE(std::filesystem::exists(dir / "report.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "report.csv"));

  const CliRun mismatch = iesrgs("eval " + renders + " " + scene);
  EXPECT_EQ(mismatch.status, 1);
  EXPECT_TRUE(contains(last_line(mismatch.output), "64x64 but its reference is 32x32"))
      << mismatch.output;

  const CliRun orbit = iesrgs("render " + out + " " + scene + " -o " + (dir / "orbit").string() +
                              " --path orbit --frames 3");
  ASSERT_EQ(orbit.status, 0) << orbit.output;
  EXPECT_TRUE(contains(orbit.output, "rendering 3 orbit path views")) << orbit.output;
  for (const char* frame : {"path_0000", "path_0001", "path_0002"})
    EXPECT_EQ(read_image_header(dir / "orbit" / "rgb" / (std::string(frame) + ".png")).width, 32)
        << frame;
  // Rendered again with fewer frames: the earlier render's last frame must not stay among them.
  ASSERT_EQ(iesrgs("render " + out + " " + scene + " -o " + (dir / "orbit").string() +
                   " --path orbit --frames 2")
                .status,
            0);
  for (const char* folder : {"rgb", "depth", "alpha"})
    EXPECT_FALSE(std::filesystem::exists(dir / "orbit" / folder / "path_0002.png")) << folder;
  EXPECT_TRUE(std::filesystem::exists(dir / "orbit" / "rgb" / "path_0001.png"));
  // A render needing about twice the available memory is refused before the kernel would kill the
  // process (64 bytes a pixel; sized from this host's memory, when it is under 128 GiB), and
  // before anything of the earlier render in the folder is removed.
  const int64_t available = available_memory_bytes();
  const int huge_scale = int(std::ceil(std::sqrt(2.0 * double(available) / 64) / 32));
  if (available > 0 && 32 * huge_scale <= 65536) {
    const CliRun huge = iesrgs("render " + out + " " + scene + " -o " + same_size +
                               " --path orbit --frames 2 --scale " + std::to_string(huge_scale));
    EXPECT_EQ(huge.status, 1);
    EXPECT_TRUE(contains(last_line(huge.output), "not enough memory: rendering")) << huge.output;
    EXPECT_TRUE(std::filesystem::exists(dir / "same" / "metrics.json"));
    EXPECT_TRUE(std::filesystem::exists(dir / "same" / "rgb" / "r_1.png"));
  }
  // A render that stopped partway is no render to score.
  const std::string record = read_file(dir / "same" / "render.json");
  auto unfinished = nlohmann::json::parse(record);
  EXPECT_EQ(unfinished["finished"], true);
  unfinished["finished"] = false;
  write_file_atomically(dir / "same" / "render.json", unfinished.dump());
  const CliRun stopped = iesrgs("eval --lpips none " + same_size + " " + scene);
  EXPECT_EQ(stopped.status, 1);
  EXPECT_TRUE(contains(last_line(stopped.output), "render.json: this render did not finish"))
      << stopped.output;
  write_file_atomically(dir / "same" / "render.json", record);
  // A render.json naming files outside its folder removes none of them.
  write_file_atomically(dir / "keep.png", "x");
  write_file_atomically(dir / "orbit" / "render.json", R"({"names": ["../../keep"]})");
  ASSERT_EQ(iesrgs("render " + out + " " + scene + " -o " + (dir / "orbit").string() +
                   " --path orbit --frames 1")
                .status,
            0);
  EXPECT_TRUE(std::filesystem::exists(dir / "keep.png"));

  // Views of other sizes than the first are checked too: here a nerfstudio frame's own width
  // (its training views are r_1 to r_5, every 8th frame by name being a test view).
  std::filesystem::copy(dir / "scene", dir / "sizes", std::filesystem::copy_options::recursive);
  auto layout = nlohmann::json::parse(read_file(dir / "sizes" / "transforms_train.json"));
  for (const char* split : {"transforms_train.json", "transforms_test.json"})
    std::filesystem::remove(dir / "sizes" / split);
  layout["frames"][2]["w"] = 40000;
  write_file_atomically(dir / "sizes" / "transforms.json", layout.dump());
  const CliRun wide = iesrgs("render " + out + " " + (dir / "sizes").string() + " -o " +
                             (dir / "wide").string() + " --split train --scale 2");
  EXPECT_EQ(wide.status, 1);
  EXPECT_TRUE(contains(last_line(wide.output), "--scale 2: view r_2 would be 80000x64 pixels"))
      << wide.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "wide"));

  // eval scores renders against the split they were made of, which render.json records.
  const CliRun path_scored = iesrgs("eval " + (dir / "orbit").string() + " " + scene);
  EXPECT_EQ(path_scored.status, 1);
  EXPECT_TRUE(contains(last_line(path_scored.output), "frames of a camera path"))
      << path_scored.output;
  const std::string train_views = (dir / "train_views").string();
  ASSERT_EQ(iesrgs("render " + out + " " + scene + " -o " + train_views + " --split train").status,
            0);
  const CliRun other_split = iesrgs("eval --lpips none " + train_views + " " + scene);
  EXPECT_EQ(other_split.status, 1);
  EXPECT_TRUE(contains(last_line(other_split.output), "of the train split, and --split test"))
      << other_split.output;
  EXPECT_EQ(iesrgs("eval --lpips none " + train_views + "/rgb/ " + scene).status, 1);
  EXPECT_EQ(iesrgs("eval --lpips none --split train " + train_views + "/rgb " + scene).status, 0);
  // A capture's test views are every --test-every-th: eval takes the renders' own, recorded.
  std::filesystem::copy(dir / "scene", dir / "capture", std::filesystem::copy_options::recursive);
  for (const char* split : {"transforms_train.json", "transforms_test.json"})
    std::filesystem::remove(dir / "capture" / split);
  write_file_atomically(dir / "capture" / "transforms.json",
                        read_file(dir / "scene" / "transforms_train.json"));
  const std::string capture = (dir / "capture").string(), held = (dir / "held").string();
  ASSERT_EQ(iesrgs("render " + out + " " + capture + " -o " + held + " --test-every 2").status, 0);
  EXPECT_EQ(iesrgs("eval --lpips none " + held + " " + capture).status, 0);
  EXPECT_EQ(iesrgs("eval --lpips none --test-every 8 " + held + " " + capture).status, 1);

  const CliRun bench = iesrgs("bench raster --model " + out + " --scene " + scene +
                              " --scale 2 --views 3 --iterations 1");
  ASSERT_EQ(bench.status, 0) << bench.output;
  EXPECT_TRUE(contains(bench.output, "3 training views of " + scene + " at 64x64")) << bench.output;
  EXPECT_TRUE(contains(bench.output, "forward+backward: ")) << bench.output;

  const auto splat = dir / "scene.splat";
  const CliRun exported = iesrgs("export " + out + " " + splat.string());
  ASSERT_EQ(exported.status, 0) << exported.output;
  EXPECT_TRUE(contains(exported.output,
                       "note: a .splat file has no place for the background the "
                       "model was trained over; render it with --background "
                       "1,1,1"))
      << exported.output;
  const size_t gaussians = read_ply(dir / "run" / "point_cloud.ply").size();
  EXPECT_EQ(std::filesystem::file_size(splat), 32 * gaussians);
  const auto spz = dir / "scene.spz";
  const CliRun compressed = iesrgs("export " + out + " " + spz.string());
  ASSERT_EQ(compressed.status, 0) << compressed.output;
  EXPECT_EQ(read_file(spz).substr(0, 2), "\x1f\x8b");  // gzip
  // The .spz is a model too: described, rendered and exported again like the .ply.
  const CliRun described = iesrgs("info " + spz.string());
  ASSERT_EQ(described.status, 0) << described.output;
  EXPECT_TRUE(contains(described.output, fmt::format("gaussians   {}", gaussians)))
      << described.output;
  EXPECT_TRUE(contains(described.output, "2D filter   Mip-Splatting's (antialiased)"))
      << described.output;
  const CliRun rendered =
      iesrgs("render " + spz.string() + " " + scene + " -o " + (dir / "from_spz").string());
  ASSERT_EQ(rendered.status, 0) << rendered.output;
  EXPECT_TRUE(contains(rendered.output, "(antialiased, ")) << rendered.output;
  const CliRun classic = iesrgs("render " + spz.string() + " " + scene + " -o " +
                                (dir / "classic").string() + " --rasterize-mode classic");
  ASSERT_EQ(classic.status, 0) << classic.output;
  EXPECT_TRUE(contains(classic.output, "(classic, ")) << classic.output;
  EXPECT_NE(read_image8(dir / "classic" / "rgb" / "r_0.png").data,
            read_image8(dir / "from_spz" / "rgb" / "r_0.png").data);
  // Quantized to a byte or so per value, the model renders as the .ply does to a few levels.
  const Image8 from_spz = read_image8(dir / "from_spz" / "rgb" / "r_0.png");
  const Image8 from_ply = read_image8(dir / "same" / "rgb" / "r_0.png");
  ASSERT_EQ(from_spz.data.size(), from_ply.data.size());
  double difference = 0;
  for (size_t i = 0; i < from_spz.data.size(); ++i)
    difference += std::abs(int(from_spz.data[i]) - int(from_ply.data[i]));
  EXPECT_LT(difference / double(from_spz.data.size()), 3.0);
  const CliRun unknown = iesrgs("export " + out + " " + (dir / "scene.obj").string());
  EXPECT_EQ(unknown.status, 1);
  EXPECT_TRUE(contains(last_line(unknown.output), "scene.obj: unknown export format"))
      << unknown.output;
}

// As 3DGS's render and metrics scripts: a model is drawn over the background it was trained over,
// and its renders scored against ground truth composited over the same.
TEST(TrainCli, RenderAndEvalTakeTheTrainingBackground) {
  TempDir dir;
  const std::string scene = (dir / "scene").string(), out = (dir / "run").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 16 --views 4 --test-views 1 --seed 2").status, 0);
  ASSERT_EQ(iesrgs("train " + scene + " -o " + out +
                   " --background black --preset fast --iterations 10 --set random_points=500"
                   " --set init=random")
                .status,
            0);
  const auto mean_psnr = [&](const std::string& renders, const std::string& options) {
    const CliRun eval = iesrgs("eval --lpips none " + options + " " + renders + " " + scene);
    EXPECT_EQ(eval.status, 0) << eval.output;
    return nlohmann::json::parse(read_file(std::filesystem::path(renders) / "metrics.json"))
        .at("mean")
        .at("psnr")
        .get<double>();
  };
  const std::string renders = (dir / "renders").string();
  const CliRun render = iesrgs("render " + out + " " + scene + " -o " + renders);
  ASSERT_EQ(render.status, 0) << render.output;
  EXPECT_TRUE(contains(render.output, "background 0,0,0)")) << render.output;
  EXPECT_EQ(nlohmann::json::parse(read_file(dir / "renders" / "render.json"))["background"],
            nlohmann::json::array({0, 0, 0}));
  const double on_black = mean_psnr(renders, "--background black");
  EXPECT_EQ(mean_psnr(renders, ""), on_black);
  EXPECT_NE(mean_psnr(renders, "--background white"), on_black);

  const CliRun white =
      iesrgs("render " + out + " " + scene + " -o " + renders + " --background white");
  ASSERT_EQ(white.status, 0) << white.output;
  EXPECT_TRUE(contains(white.output, "background 1,1,1)")) << white.output;
}

TEST(TrainCli, VerboseSaysWhatDensificationDoes) {
  TempDir dir;
  const std::string scene = (dir / "scene").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 16 --views 4 --test-views 1 --seed 2").status, 0);
  // 400 iterations: densification from 7 until 200, every 100 iterations, so once, and the
  // opacity reset, pro rata every 40 iterations, held to the densification step.
  const std::string train = "train " + scene + " -o " + (dir / "run").string() +
                            " --preset fast --iterations 400 --set random_points=500";
  const CliRun verbose = iesrgs("-v " + train);
  ASSERT_EQ(verbose.status, 0) << verbose.output;
  EXPECT_TRUE(contains(verbose.output, "iteration 100: densification cloned ")) << verbose.output;
  EXPECT_TRUE(contains(verbose.output, "iteration 100: opacities reset")) << verbose.output;
  EXPECT_FALSE(contains(verbose.output, "iteration 40: opacities reset")) << verbose.output;
  const CliRun quiet = iesrgs(train);
  ASSERT_EQ(quiet.status, 0) << quiet.output;
  EXPECT_FALSE(contains(quiet.output, "densification")) << quiet.output;
}

TEST(TrainCli, ResumeOfAFinishedRunKeepsItsModelAndReport) {
  TempDir dir;
  const std::string scene = (dir / "scene").string(), out = (dir / "run").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 24 --views 4 --test-views 1").status, 0);
  const std::string train = "train " + scene + " -o " + out;
  ASSERT_EQ(
      iesrgs(train + " --preset fast --iterations 10 --set random_points=500 --set init=random")
          .status,
      0);
  const auto report = nlohmann::json::parse(read_file(dir / "run" / "training.json"));
  const std::string model = read_file(dir / "run" / "point_cloud.ply");
  // A folder with a checkpoint and no model yet is a training to resume, not a missing file.
  std::filesystem::create_directories(dir / "unfinished");
  std::filesystem::copy_file(dir / "run" / "checkpoint.pt", dir / "unfinished" / "checkpoint.pt");
  for (const std::string command : {"info ", "export "}) {
    const CliRun unfinished =
        iesrgs(command + (dir / "unfinished").string() + (command == "export " ? " x.splat" : ""));
    EXPECT_EQ(unfinished.status, 1) << command;
    EXPECT_TRUE(contains(last_line(unfinished.output), "its training has not finished"))
        << unfinished.output;
  }
  const CliRun resumed = iesrgs(train + " --resume");
  ASSERT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_TRUE(contains(resumed.output, "resuming")) << resumed.output;
  EXPECT_FALSE(contains(resumed.output, "random points")) << resumed.output;  // the checkpoint's
  EXPECT_EQ(read_file(dir / "run" / "point_cloud.ply"), model);
  const auto again = nlohmann::json::parse(read_file(dir / "run" / "training.json"));
  for (const char* key : {"iterations", "gaussians", "final_loss", "test_psnr"})
    EXPECT_EQ(again[key], report[key]) << key;
  EXPECT_GT(again["test_psnr"].get<double>(), 0.0);
  EXPECT_GT(again["iterations_per_second"].get<double>(), 0.0);

  // The run's own command again, as the interruption message says, is a resume; other options
  // are refused, naming what they would change.
  const CliRun same = iesrgs(
      train + " --preset fast --iterations 10 --set random_points=500 --set init=random --resume");
  ASSERT_EQ(same.status, 0) << same.output;
  EXPECT_EQ(read_file(dir / "run" / "point_cloud.ply"), model);
  const CliRun longer = iesrgs(train + " --resume --preset fast --iterations 20");
  EXPECT_EQ(longer.status, 1);
  EXPECT_TRUE(contains(last_line(longer.output), "would change it (") &&
              contains(last_line(longer.output), "iterations 20 instead of 10"))
      << longer.output;
  // Without a schedule, the options given are compared on top of the run's own.
  const CliRun reseeded = iesrgs(train + " --resume --seed 5");
  EXPECT_EQ(reseeded.status, 1);
  EXPECT_TRUE(contains(last_line(reseeded.output), "would change it (seed 5 instead of 0);"))
      << reseeded.output;
  const CliRun repeated = iesrgs(train + " --resume --set random_points=500 --iterations 10");
  EXPECT_EQ(repeated.status, 0) << repeated.output;
  // How the run reports and checkpoints may change, and the saved config says how it now does.
  const CliRun reporting = iesrgs(train + " --resume --set checkpoint_every=3 --set log_every=1");
  ASSERT_EQ(reporting.status, 0) << reporting.output;
  EXPECT_EQ(read_file(dir / "run" / "point_cloud.ply"), model);
  EXPECT_EQ(nlohmann::json::parse(read_file(dir / "run" / "config.json"))["checkpoint_every"], 3);
  const CliRun doubled = iesrgs(train + " --resume --iterations 20");
  EXPECT_EQ(doubled.status, 1);
  EXPECT_TRUE(contains(last_line(doubled.output), "iterations 20 instead of 10") &&
              !contains(last_line(doubled.output), "preset"))
      << doubled.output;
  const CliRun halved = iesrgs(train + " --resume --downscale 2");
  EXPECT_EQ(halved.status, 1);
  EXPECT_TRUE(contains(last_line(halved.output), "cameras.json: the run trained on other cameras"))
      << halved.output;
  const CliRun black = iesrgs(train + " --resume --background black");
  EXPECT_EQ(black.status, 1);
  EXPECT_TRUE(contains(last_line(black.output), "the run trained over the background 1,1,1"))
      << black.output;

  // A new run into the folder replaces the earlier one whole: no checkpoint of it is left for a
  // --resume to continue under the new config, and the log starts again. The user is told.
  const CliRun replaced = iesrgs(train + " --preset fast --iterations 5 --set random_points=500");
  ASSERT_EQ(replaced.status, 0) << replaced.output;
  EXPECT_TRUE(contains(replaced.output, "replaced the earlier run there")) << replaced.output;
  EXPECT_EQ(read_file(dir / "run" / "train_log.csv").find("\n10,"), std::string::npos);
  EXPECT_EQ(nlohmann::json::parse(read_file(dir / "run" / "training.json"))["iterations"], 5);
}

// A second process writing into a folder in use (a resume started while the run goes on) would
// interleave checkpoints and logs.
TEST(TrainCli, AFolderInUseIsRefused) {
  TempDir dir;
  const std::string scene = (dir / "scene").string(), out = (dir / "run").string();
  const std::string model = (dir / "model").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 16 --views 3 --test-views 1").status, 0);
  ASSERT_EQ(iesrgs("train " + scene + " -o " + model + " --iterations 10").status, 0);
  const FolderLock held(dir / "run");
  for (const std::string& command : {"train " + scene + " -o " + out + " --iterations 10",
                                     "run " + scene + " -o " + out + " --sr-model bicubic",
                                     "external " + scene + " -o " + out + " --sr-model bicubic",
                                     "render " + model + " " + scene + " -o " + out}) {
    const CliRun refused = iesrgs(command);
    EXPECT_EQ(refused.status, 1) << command;
    EXPECT_TRUE(contains(last_line(refused.output), out + ": in use by another process"))
        << refused.output;
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir / "run"));
}

TEST(TrainCli, BadConfigAndMissingCheckpointAreOneLineErrors) {
  TempDir dir;
  const std::string scene = (dir / "scene").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 16 --views 3 --test-views 1").status, 0);
  const CliRun typo =
      iesrgs("train " + scene + " -o " + (dir / "a").string() + " --set itrations=5");
  EXPECT_EQ(typo.status, 1);
  EXPECT_TRUE(contains(last_line(typo.output), "unknown training parameter \"itrations\""))
      << typo.output;
  // An option and a --set of the parameter it sets: neither silently wins.
  const CliRun twice =
      iesrgs("train " + scene + " -o " + (dir / "a").string() + " --seed 2 --set seed=9");
  EXPECT_EQ(twice.status, 1);
  EXPECT_TRUE(contains(last_line(twice.output), "--seed and --set seed=9 both set seed"))
      << twice.output;
  const CliRun resume = iesrgs("train " + scene + " -o " + (dir / "b").string() + " --resume");
  EXPECT_EQ(resume.status, 1);
  EXPECT_TRUE(contains(last_line(resume.output), "config.json: missing")) << resume.output;
  // A saved config edited out of range is named on --resume.
  write_file_atomically(dir / "b" / "config.json", R"({"max_sh_degree": 7})");
  const CliRun edited = iesrgs("train " + scene + " -o " + (dir / "b").string() + " --resume");
  EXPECT_EQ(edited.status, 1);
  EXPECT_TRUE(contains(last_line(edited.output),
                       "config.json: invalid training config: max_sh_degree must be 0..3"))
      << edited.output;
  // A config file naming another preset would relabel the run's schedule.
  write_file_atomically(dir / "paper.json", R"({"preset": "paper", "seed": 3})");
  const CliRun relabel = iesrgs("train " + scene + " -o " + (dir / "d").string() + " --config " +
                                (dir / "paper.json").string());
  EXPECT_EQ(relabel.status, 1);
  EXPECT_TRUE(contains(last_line(relabel.output),
                       "paper.json: its preset \"paper\" is not this run's \"cpu\""))
      << relabel.output;
  // Out-of-range numbers are refused before any work, in words.
  const CliRun none = iesrgs("train " + scene + " -o " + (dir / "c").string() + " --iterations 0");
  EXPECT_NE(none.status, 0);
  EXPECT_TRUE(contains(none.output, "--iterations: must be greater than 0, got 0")) << none.output;
  const CliRun negative = iesrgs("train " + scene + " -o " + (dir / "c").string() + " --seed -5");
  EXPECT_NE(negative.status, 0);
  EXPECT_TRUE(contains(negative.output, "--seed: must be at least 0, got -5")) << negative.output;
  const CliRun bright =
      iesrgs("train " + scene + " -o " + (dir / "c").string() + " --background 2,0,0.5");
  EXPECT_EQ(bright.status, 1);
  EXPECT_TRUE(contains(last_line(bright.output), "each of r,g,b must be in [0, 1], got '2,0,0.5'"))
      << bright.output;
  const CliRun huge = iesrgs("train " + scene + " -o " + (dir / "c").string() +
                             " --set init=random --set random_points=2000000000");
  EXPECT_EQ(huge.status, 1);
  // Host memory on the CPU, "not enough GPU memory" where --device auto takes a GPU.
  EXPECT_TRUE(contains(last_line(huge.output), "memory: training 2000000000 Gaussians needs about"))
      << huge.output;
  EXPECT_TRUE(contains(last_line(huge.output), "error: not enough ")) << huge.output;
  const CliRun model = iesrgs("render " + (dir / "nothing.ply").string() + " " + scene + " -o " +
                              (dir / "r").string());
  EXPECT_EQ(model.status, 1);
  EXPECT_TRUE(contains(last_line(model.output), "nothing.ply")) << model.output;
}

}  // namespace
}  // namespace iesrgs
