// End-to-end checks of the iesrgs binary: exit codes and one-line errors as a user sees them.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>

#include "core/memory.hpp"
#include "io/atomic_file.hpp"
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
using testing::write_text;

TEST(Cli, InfoHelpExplainsTheOptions) {
  const CliRun run = iesrgs("info --help");
  EXPECT_EQ(run.status, 0);
  EXPECT_TRUE(contains(run.output, "--load-images")) << run.output;
  EXPECT_TRUE(contains(run.output, "--downscale")) << run.output;
}

// One command line serves every pipeline stage, but `internal` lists the options it does not use
// under their own heading, after its own.
TEST(Cli, InternalHelpSetsTheOtherStagesOptionsApart) {
  const CliRun run = iesrgs("internal --help");
  EXPECT_EQ(run.status, 0);
  const size_t heading = run.output.find("Options of the other stages (accepted, unused here):");
  ASSERT_NE(heading, std::string::npos) << run.output;
  EXPECT_LT(run.output.find("--internal-iterations"), heading) << run.output;
  EXPECT_LT(run.output.find("--seed"), heading) << run.output;
  for (const char* unused : {"--sr-model", "--iterations", "--threshold", "--rows", "--lpips"}) {
    const size_t at = run.output.find(std::string(" ") + unused);
    EXPECT_TRUE(at != std::string::npos && at > heading) << unused;
  }
  EXPECT_EQ(iesrgs("run --help").output.find("Options of the other stages"), std::string::npos);
}

// train's --resume, carried over to the pipeline, says what to do, and creates nothing.
TEST(Cli, PipelineCommandsAnswerResumeWithWhatToDo) {
  TempDir dir;
  for (const std::string command : {"run", "internal", "fuse"}) {
    const CliRun run = iesrgs(command + " " + (dir / "scene").string() + " -o " +
                              (dir / "out").string() + " --resume");
    EXPECT_EQ(run.status, 1) << command;
    EXPECT_EQ(last_line(run.output), "error: " + command +
                                         " has no --resume: it resumes by itself; run the same "
                                         "command without it")
        << run.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  EXPECT_EQ(iesrgs("run --help").output.find("--resume"), std::string::npos);
}

TEST(Cli, VersionSaysWhichDeviceAutoTakes) {
  const CliRun run = iesrgs("--version");
  EXPECT_EQ(run.status, 0);
  EXPECT_TRUE(contains(run.output, "iesrgs 0.1.0\nCUDA kernels: ")) << run.output;
  EXPECT_TRUE(contains(run.output, "--device auto: ")) << run.output;
}

// CLI11 alone says "A subcommand is required" to a misspelled command.
TEST(Cli, AnUnknownCommandIsNamedWithTheKnownOnes) {
  const CliRun command = iesrgs("tran scene -o out");
  EXPECT_NE(command.status, 0);
  EXPECT_TRUE(contains(last_line(command.output), "error: unknown command 'tran' (known: synth, "))
      << command.output;
  EXPECT_TRUE(contains(last_line(command.output), " train, ")) << command.output;
  EXPECT_EQ(last_line(iesrgs("bench rastr").output),
            "error: unknown bench mode 'rastr' (known: raster, ssim, adam)");
  EXPECT_TRUE(contains(last_line(iesrgs("").output), "error: no command given (known: "));
  EXPECT_EQ(last_line(iesrgs("bench -n 5").output),
            "error: unknown option '-n' (--help lists the options)");
}

// A full disk behind stdout: help and a printed summary fail rather than claim success.
TEST(Cli, AFullStandardOutputIsAFailure) {
  EXPECT_EQ(iesrgs("--help > /dev/full").status, 1);
  EXPECT_EQ(iesrgs("--version > /dev/full").status, 1);
  EXPECT_EQ(iesrgs("bench adam --gaussians 100 --iterations 1 > /dev/full").status, 1);
  EXPECT_EQ(iesrgs("--help > /dev/null").status, 0);
}

TEST(Cli, MissingSceneIsOneLineNamingThePath) {
  TempDir dir;
  const CliRun run = iesrgs("info " + (dir / "nowhere").string());
  EXPECT_EQ(run.status, 1);
  EXPECT_EQ(last_line(run.output),
            "error: " + (dir / "nowhere").string() + ": scene directory not found");
  write_text(dir / "a.png", "x");  // a file, not a scene
  EXPECT_EQ(last_line(iesrgs("info " + (dir / "a.png").string()).output),
            "error: " + (dir / "a.png").string() +
                ": not a scene: give a scene's folder, or its transforms .json file");
}

// An empty -o would write into the working folder.
TEST(Cli, EmptyOutputFolderIsRefused) {
  for (const char* command :
       {"synth -o ''", "train scene -o ''", "run scene -o ''", "render model scene -o ''",
        "external scene -o ''", "eval renders scene -o ''"}) {
    const CliRun run = iesrgs(command);
    EXPECT_NE(run.status, 0) << command;
    EXPECT_EQ(last_line(run.output),
              "error: --output: must not be empty (--help lists the options)")
        << command;
  }
  for (const char* command : {"upscale --model bicubic a.png ''", "depth a.png ''"}) {
    const CliRun run = iesrgs(command);
    EXPECT_NE(run.status, 0) << command;
    EXPECT_TRUE(contains(last_line(run.output), "must not be empty")) << command << run.output;
  }
}

TEST(Cli, SynthSceneLoadsAndDecodes) {
  TempDir dir;
  const std::string scene = (dir / "scene").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 32 --views 3 --test-views 2 --seed 3").status, 0);
  const CliRun info = iesrgs("info " + scene + " --load-images");
  EXPECT_EQ(info.status, 0) << info.output;
  EXPECT_TRUE(contains(info.output, "cameras     5 (3 train, 2 test)")) << info.output;
  EXPECT_TRUE(contains(info.output, "image size  32x32")) << info.output;
  // A NeRF Synthetic scene without SfM points starts in 3DGS's cube.
  EXPECT_TRUE(contains(
      info.output,
      "start       random points in the cube of half-size 1.300 around (0.000, 0.000, 0.000)"))
      << info.output;
  EXPECT_TRUE(contains(info.output, "all 5 decoded")) << info.output;
}

TEST(Cli, LoadImagesStopsAtTheFirstBadImage) {
  TempDir dir;
  const std::string scene = (dir / "scene").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 32 --views 3 --test-views 1").status, 0);
  const auto bad = dir / "scene" / "train" / "r_1.png";
  write_text(bad, read_file(bad).substr(0, 60));  // truncated
  const CliRun info = iesrgs("info " + scene + " --load-images");
  EXPECT_EQ(info.status, 1);
  EXPECT_TRUE(contains(last_line(info.output), "error: " + bad.string() + ": not a readable"))
      << info.output;
}

TEST(Cli, BadDownscaleIsRejected) {
  const CliRun run = iesrgs("info . --downscale 0");
  EXPECT_NE(run.status, 0);
  EXPECT_TRUE(contains(run.output, "--downscale")) << run.output;
}

TEST(Cli, BenchModesPrintTheirTimings) {
  const CliRun raster =
      iesrgs("bench raster --gaussians 200 --width 48 --height 32 --iterations 2");
  EXPECT_EQ(raster.status, 0) << raster.output;
  EXPECT_TRUE(contains(raster.output, "scene: synthetic, 200 Gaussians, 48x32")) << raster.output;
  EXPECT_TRUE(contains(raster.output, "forward+backward: ")) << raster.output;
  const CliRun ssim = iesrgs("bench ssim --width 40 --height 24 --iterations 2 --threads 1");
  EXPECT_EQ(ssim.status, 0) << ssim.output;
  EXPECT_TRUE(contains(ssim.output, "image: 40x24 RGB, 1 threads")) << ssim.output;
  EXPECT_TRUE(contains(ssim.output, "row loops: ")) << ssim.output;
  EXPECT_TRUE(contains(ssim.output, "forward+backward: ")) << ssim.output;
  const CliRun adam = iesrgs("bench adam --gaussians 100 --iterations 2");
  EXPECT_EQ(adam.status, 0) << adam.output;
  EXPECT_TRUE(contains(adam.output, "model: 100 Gaussians (5900 floats)")) << adam.output;
  EXPECT_TRUE(contains(adam.output, "Adam step: ")) << adam.output;
}

TEST(Cli, BenchRefusesAFrameBeyondTheMachinesMemory) {
  const CliRun huge = iesrgs("bench raster --gaussians 10 --width 800000 --height 800000");
  EXPECT_EQ(huge.status, 1);
  EXPECT_TRUE(contains(last_line(huge.output),
                       "error: not enough memory: a 800000x800000 frame needs about 28610.2 GiB"))
      << huge.output;
}

TEST(Cli, BenchRefusesEmptyWork) {
  const CliRun narrow = iesrgs("bench ssim --width 0");
  EXPECT_EQ(narrow.status, 105);
  EXPECT_TRUE(contains(narrow.output, "--width: must be greater than 0, got 0")) << narrow.output;
  const CliRun none = iesrgs("bench adam --iterations 0");
  EXPECT_EQ(none.status, 105);
  EXPECT_TRUE(contains(none.output, "--iterations: must be greater than 0, got 0")) << none.output;
  const CliRun threads = iesrgs("bench raster --threads -1");
  EXPECT_EQ(threads.status, 105);
  EXPECT_TRUE(contains(threads.output, "--threads: must be at least 0, got -1")) << threads.output;
  const CliRun crowd = iesrgs("bench ssim --threads 100000");
  EXPECT_EQ(crowd.status, 105);
  EXPECT_TRUE(contains(crowd.output, "100000 not in range 0 to 1024")) << crowd.output;
  const CliRun alone = iesrgs("bench raster --model nowhere.ply");
  EXPECT_EQ(alone.status, 107);
  EXPECT_TRUE(contains(alone.output, "--model requires --scene")) << alone.output;
}

TEST(Cli, UpscaleWritesOnePngPerImageOfAFolder) {
  TempDir dir;
  write_png(dir / "in" / "a.png", Image8(10, 8, 4));
  write_png(dir / "in" / "b.png", Image8(6, 5, 3));
  write_text(dir / "in" / "notes.txt", "not an image");
  const CliRun run = iesrgs("upscale --model bicubic --scale 2 " + (dir / "in").string() + " " +
                            (dir / "out").string());
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "[2/2]")) << run.output;
  const Image8 a = read_image8(dir / "out" / "a.png");
  const Image8 b = read_image8(dir / "out" / "b.png");
  EXPECT_EQ(std::make_tuple(a.width, a.height, a.channels), std::make_tuple(20, 16, 3));
  EXPECT_EQ(std::make_tuple(b.width, b.height, b.channels), std::make_tuple(12, 10, 3));
}

TEST(Cli, UpscaleRefusesTwoImagesOfOneStem) {
  TempDir dir;
  write_png(dir / "in" / "a.png", Image8(4, 4, 3));
  write_text(dir / "in" / "a.jpg", "decoded only once the names are checked");
  const CliRun run = iesrgs("upscale --model bicubic --scale 2 " + (dir / "in").string() + " " +
                            (dir / "out").string());
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_EQ(last_line(run.output), "error: " + (dir / "out" / "a.png").string() +
                                       ": would be written twice, for " +
                                       (dir / "in" / "a.jpg").string() + " and for " +
                                       (dir / "in" / "a.png").string() + "; rename one");
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "a.png"));
}

TEST(Cli, UpscaleOfAMissingInputNamesIt) {
  TempDir dir;
  const CliRun run =
      iesrgs("upscale --model bicubic " + (dir / "nothing.png").string() + " out.png");
  EXPECT_EQ(run.status, 1);
  EXPECT_EQ(last_line(run.output),
            "error: " + (dir / "nothing.png").string() + ": no such image or folder");
}

TEST(Cli, UpscaleNeverWritesOverItsInputNorPngBytesUnderAnotherName) {
  TempDir dir;
  const std::string image = (dir / "in" / "a.png").string();
  write_png(image, Image8(6, 4, 3));
  const std::string before = read_file(image);
  for (const std::string& output : {image, (dir / "in").string()}) {
    const CliRun run = iesrgs("upscale --model bicubic --scale 2 " + image + " " + output);
    EXPECT_EQ(run.status, 1) << run.output;
    EXPECT_EQ(last_line(run.output),
              "error: " + image + ": is an input image; write the results elsewhere");
  }
  const CliRun folder = iesrgs("upscale --model bicubic --scale 2 " + (dir / "in").string() + " " +
                               (dir / "in").string());
  EXPECT_EQ(folder.status, 1) << folder.output;
  EXPECT_EQ(read_file(image), before);
  const std::string jpeg = (dir / "a.jpg").string();
  const CliRun named = iesrgs("upscale --model bicubic --scale 2 " + image + " " + jpeg);
  EXPECT_EQ(named.status, 1) << named.output;
  EXPECT_TRUE(contains(last_line(named.output), jpeg + ": upscale writes .png files"))
      << named.output;
  EXPECT_FALSE(std::filesystem::exists(jpeg));
}

TEST(Cli, UpscaleRefusesAnOutputTooLargeBeforeUpscaling) {
  TempDir dir;
  const std::string image = (dir / "a.png").string(), output = (dir / "out.png").string();
  write_png(image, Image8(60, 40, 3));
  const CliRun huge = iesrgs("upscale --model bicubic --scale 2000000000 " + image + " " + output);
  EXPECT_EQ(huge.status, 1);
  EXPECT_EQ(last_line(huge.output),
            "error: " + image +
                ": upscaled, it would be 120000000000x80000000000 pixels (at most 65536 a side)");
  // An output that fits a PNG but needs about twice the available memory (32 bytes a pixel;
  // sized from this host's memory, when it is under 2 TiB).
  const int64_t available = available_memory_bytes();
  const int scale = int(std::ceil(std::sqrt(2.0 * double(available) / (60 * 40 * 32))));
  if (available > 0 && 60 * scale <= 65536) {
    const CliRun big = iesrgs("upscale --model bicubic --scale " + std::to_string(scale) + " " +
                              image + " " + output);
    EXPECT_EQ(big.status, 1);
    EXPECT_TRUE(contains(last_line(big.output), "not enough memory: upscaling " + image))
        << big.output;
  }
  EXPECT_FALSE(std::filesystem::exists(output));
}

TEST(Cli, ExportNeverWritesOverItsModel) {
  TempDir dir;
  SplatCloud cloud;
  cloud.positions = {0, 0, 0};
  cloud.sh_dc = {0.5f, 0.5f, 0.5f};
  cloud.opacity = {0};
  cloud.log_scales = {-2, -2, -2};
  cloud.rotations = {1, 0, 0, 0};
  write_ply(dir / "model.ply", cloud);
  const std::string before = read_file(dir / "model.ply");
  const std::string model = (dir / "model.ply").string();
  const CliRun run = iesrgs("export " + model + " " + model);
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_EQ(last_line(run.output),
            "error: " + model + ": is the model being exported; write the export elsewhere");
  EXPECT_EQ(read_file(dir / "model.ply"), before);
}

TEST(Cli, ExportOfAnEmptyModelWritesNothing) {
  TempDir dir;
  write_ply(dir / "empty.ply", SplatCloud());
  const std::string output = (dir / "empty.splat").string();
  const CliRun run = iesrgs("export " + (dir / "empty.ply").string() + " " + output);
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_EQ(last_line(run.output),
            "error: " + (dir / "empty.ply").string() + ": holds no Gaussians: nothing to export");
  EXPECT_FALSE(std::filesystem::exists(output));
}

TEST(Cli, InfoOfAModelSummarizesItsGaussians) {
  TempDir dir;
  SplatCloud cloud;
  cloud.positions = {-1, 0, 2, 3, -4, 5};
  cloud.sh_dc = {0, 0, 0, 0, 0, 0};
  cloud.opacity = {0, 0};
  cloud.log_scales = {0, -1, -2, 0, 0, 0};
  cloud.rotations = {1, 0, 0, 0, 1, 0, 0, 0};
  cloud.background = std::array<float, 3>{0, 0.5f, 1};
  write_ply(dir / "model.ply", cloud);
  const CliRun run = iesrgs("info " + (dir / "model.ply").string());
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "gaussians   2\nsh degree   0\n3D filter   no")) << run.output;
  EXPECT_TRUE(contains(run.output, "(-1.000, -4.000, 2.000) to (3.000, 0.000, 5.000)"))
      << run.output;
  EXPECT_TRUE(contains(run.output, "opacity     median 0.500")) << run.output;
  EXPECT_TRUE(contains(run.output, "background  0 0.5 1 (trained over)")) << run.output;

  // A training folder is summarized by its point_cloud.ply.
  std::filesystem::create_directories(dir / "run");
  std::filesystem::rename(dir / "model.ply", dir / "run" / "point_cloud.ply");
  const CliRun folder = iesrgs("info " + (dir / "run").string());
  EXPECT_EQ(folder.status, 0) << folder.output;
  EXPECT_TRUE(contains(folder.output, "point_cloud.ply\ngaussians   2\n")) << folder.output;
}

TEST(Cli, EvalCompositesRgbaRendersOverTheBackground) {
  TempDir dir;
  Image8 transparent(8, 8, 4);  // black, alpha 0: the background everywhere
  Image8 white(8, 8, 3);
  std::fill(white.data.begin(), white.data.end(), uint8_t(255));
  write_png(dir / "renders" / "r_0.png", transparent);
  write_png(dir / "truth" / "r_0.png", white);
  const std::string folders = (dir / "renders").string() + " " + (dir / "truth").string();
  const CliRun on_white = iesrgs("eval --lpips none " + folders);
  EXPECT_EQ(on_white.status, 0) << on_white.output;
  EXPECT_TRUE(contains(on_white.output, "1 view: PSNR inf dB, SSIM 1.0000")) << on_white.output;
  const CliRun on_black = iesrgs("eval --lpips none --background black " + folders);
  EXPECT_EQ(on_black.status, 0) << on_black.output;
  EXPECT_TRUE(contains(on_black.output, "1 view: PSNR 0.000 dB")) << on_black.output;
  // By default, the background the renders were drawn over, as their render.json records it.
  write_text(dir / "renders" / "render.json", R"({"finished": true, "background": [0, 0, 0]})");
  const CliRun recorded = iesrgs("eval --lpips none " + folders);
  EXPECT_EQ(recorded.status, 0) << recorded.output;
  EXPECT_TRUE(contains(recorded.output, "1 view: PSNR 0.000 dB")) << recorded.output;
  std::filesystem::remove(dir / "renders" / "render.json");

  // Against a capture, the scene's background (black): the held-out photo, with white
  // transparent pixels where it shows the background, scores as the photo itself.
  const std::string capture = (dir / "capture").string();
  ASSERT_EQ(
      iesrgs("synth -o " + capture + " --size 16 --views 7 --test-views 1 --format colmap").status,
      0);
  const Image8 photo = read_image8(dir / "capture" / "images" / "r_0000.png");
  Image8 rgba(photo.width, photo.height, 4);
  size_t transparent_pixels = 0;
  for (int y = 0; y < photo.height; ++y)
    for (int x = 0; x < photo.width; ++x) {
      const bool background = photo.at(x, y, 0) + photo.at(x, y, 1) + photo.at(x, y, 2) == 0;
      transparent_pixels += background;
      for (int c = 0; c < 3; ++c) rgba.at(x, y, c) = background ? 255 : photo.at(x, y, c);
      rgba.at(x, y, 3) = background ? 0 : 255;
    }
  ASSERT_GT(transparent_pixels, 0u);
  write_png(dir / "capture_renders" / "r_0000.png", rgba);
  const CliRun on_capture =
      iesrgs("eval --lpips none " + (dir / "capture_renders").string() + " " + capture);
  EXPECT_EQ(on_capture.status, 0) << on_capture.output;
  EXPECT_TRUE(contains(on_capture.output, "1 view: PSNR inf dB")) << on_capture.output;
}

// The report never replaces what eval reads: the scene's split file, the renders' record.
TEST(Cli, EvalWritesNoReportOverItsInputs) {
  TempDir dir;
  const std::string scene = (dir / "scene").string(), renders = (dir / "renders").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 16 --views 2 --test-views 1").status, 0);
  write_png(dir / "renders" / "r_0.png", Image8(16, 16, 3));
  write_text(dir / "renders" / "render.json", R"({"finished": true, "split": "test"})");
  const std::string split_file = read_file(dir / "scene" / "transforms_test.json");
  // A bare name, from inside the scene: its parent is the working folder.
  const std::filesystem::path working = std::filesystem::current_path();
  std::filesystem::current_path(dir / "scene");
  const CliRun into_scene = iesrgs("eval --lpips none ../renders . -o transforms_test");
  std::filesystem::current_path(working);
  EXPECT_EQ(into_scene.status, 1) << into_scene.output;
  EXPECT_TRUE(contains(last_line(into_scene.output),
                       "transforms_test: is in the scene's own folder, whose files the report "
                       "could replace"))
      << into_scene.output;
  EXPECT_EQ(read_file(dir / "scene" / "transforms_test.json"), split_file);
  const CliRun over_record =
      iesrgs("eval --lpips none " + renders + " " + scene + " -o " + renders + "/render.csv");
  EXPECT_EQ(over_record.status, 1) << over_record.output;
  EXPECT_TRUE(contains(last_line(over_record.output), "would replace the renders' render.json"))
      << over_record.output;
  EXPECT_EQ(iesrgs("eval --lpips none " + renders + " " + scene).status, 0);  // metrics.json
  // An output that cannot be written is named before any view is scored.
  write_text(dir / "afile", "x");
  const CliRun blocked =
      iesrgs("eval --lpips none " + renders + " " + scene + " -o " + (dir / "afile/m").string());
  EXPECT_EQ(blocked.status, 1);
  EXPECT_TRUE(contains(last_line(blocked.output), "afile: cannot create the folder"))
      << blocked.output;
  EXPECT_FALSE(contains(blocked.output, "evaluated")) << blocked.output;
  const std::string nowhere = (dir / "nowhere").string();
  EXPECT_EQ(last_line(iesrgs("eval --lpips none " + nowhere + " " + scene).output),
            "error: " + nowhere + ": renders not found");
}

TEST(Cli, EvalOfPartOfASplitNamesTheViewsLeftOut) {
  TempDir dir;
  const std::string scene = (dir / "scene").string();
  ASSERT_EQ(iesrgs("synth -o " + scene + " --size 16 --views 2 --test-views 2").status, 0);
  write_text(dir / "renders" / "r_0.png", read_file(dir / "scene" / "test" / "r_0.png"));
  const CliRun run = iesrgs("eval --lpips none " + (dir / "renders").string() + " " + scene);
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(run.output,
                       "1 view of the test split has no render and is not in the "
                       "mean: r_1\n1 view: PSNR inf dB"))
      << run.output;
  const auto report = nlohmann::json::parse(read_file(dir / "renders" / "metrics.json"));
  EXPECT_EQ(report["unscored_views"], nlohmann::json::array({"r_1"}));

  // The same against a plain folder of images, the report written into a folder given as -o.
  const std::string truth = (dir / "scene" / "test").string();
  const CliRun folder = iesrgs("eval --lpips none " + (dir / "renders").string() + " " + truth +
                               " -o " + (dir / "scores").string() + "/");
  EXPECT_EQ(folder.status, 0) << folder.output;
  EXPECT_TRUE(contains(folder.output, "1 view of " + truth + " has no render")) << folder.output;
  EXPECT_EQ(nlohmann::json::parse(read_file(dir / "scores" / "metrics.json"))["unscored_views"],
            nlohmann::json::array({"r_1"}));

  // Two renders of one view would count it twice in the mean.
  write_text(dir / "renders" / "r_0.jpg", "refused before it is decoded");
  const CliRun twice = iesrgs("eval --lpips none " + (dir / "renders").string() + " " + scene);
  EXPECT_EQ(twice.status, 1);
  EXPECT_TRUE(contains(last_line(twice.output), "r_0.jpg and r_0.png are both renders of view r_0"))
      << twice.output;

  const CliRun nowhere =
      iesrgs("eval --lpips none " + (dir / "renders").string() + " " + (dir / "none").string());
  EXPECT_EQ(nowhere.status, 1);
  EXPECT_TRUE(contains(last_line(nowhere.output), "none: ground truth not found"))
      << nowhere.output;
}

}  // namespace
}  // namespace iesrgs
