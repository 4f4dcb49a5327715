// iesrgs upscale: 2D super-resolution of one image or a folder of images with any backend of
// the registry (bicubic, SAFMN, IMDN, PAN, SwinIR, ...), tiled so large inputs fit in memory.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cli/commands.hpp"
#include "cli/shared_options.hpp"
#include "cli/validators.hpp"
#include "core/error.hpp"
#include "core/memory.hpp"
#include "core/progress.hpp"
#include "io/camera.hpp"
#include "io/image.hpp"
#include "io/image_jobs.hpp"
#include "io/image_tensor.hpp"
#include "priors/sr/registry.hpp"
#include "priors/sr/sr_net.hpp"
#include "priors/sr/tiling.hpp"

namespace iesrgs::cli {

namespace {

namespace fs = std::filesystem;
using priors::sr::SrNet;

struct UpscaleArgs {
  std::string model;
  fs::path weights;
  int scale = 4;
  priors::sr::TileOptions tiles = priors::sr::kDefaultTiles;
  float background = 1.f;
  fs::path input, output;
  std::string device = "auto";
};

// The jobs, none of which may write over an input or another's result.
std::vector<ImageJob> plan_jobs(const fs::path& input, const fs::path& output) {
  std::vector<ImageJob> jobs = plan_image_jobs(input, output, ".png", "upscale");
  refuse_overwrites(jobs);
  return jobs;
}

// The output tensor, its 8-bit copy and the PNG being encoded: 25 bytes a pixel, measured with
// bicubic as the growth of the peak resident memory from 4096x4096 to 8192x8192 outputs, and a
// margin for what the networks add (one tile's activations, the input).
constexpr int64_t kUpscaleBytesPerPixel = 32;

// Refuses, before upscaling, an output larger than any image read here or than the memory.
void require_output_fits(const ImageJob& job, int64_t width, int64_t height) {
  if (std::max(width, height) > kMaxImageSide)
    fail_file(job.input, fmt::format("upscaled, it would be {}x{} pixels (at most {} a side)",
                                     width, height, kMaxImageSide));
  require_memory(width * height * kUpscaleBytesPerPixel,
                 fmt::format("upscaling {} to {}x{}", job.input.string(), width, height));
}

// Decodes, composites any alpha over the background, upscales and writes one image.
std::pair<int, int> upscale_one(SrNet& net, const UpscaleArgs& args, const ImageJob& job) {
  const float background[3] = {args.background, args.background, args.background};
  const Image rgb = composite_rgb(read_image8(job.input), background);
  require_output_fits(job, int64_t(rgb.width) * args.scale, int64_t(rgb.height) * args.scale);
  const torch::Tensor upscaled = priors::sr::upscale_tiled(net, to_tensor(rgb), args.tiles);
  write_png(job.outputs[0], to_image8(upscaled));
  return {rgb.width, rgb.height};
}

void run(const UpscaleArgs& args) {
  use_device(args.device);
  const std::vector<ImageJob> jobs = plan_jobs(args.input, args.output);
  const auto lock = lock_results_folder(args.input, args.output);
  const std::unique_ptr<SrNet> net = priors::sr::make_sr_net(args.model, args.weights, args.scale);
  ItemPace pace(jobs.size());
  for (size_t i = 0; i < jobs.size(); ++i) {
    const auto [width, height] = upscale_one(*net, args, jobs[i]);
    fmt::print("[{}/{}] {} {}x{} -> {} {}x{} ({})\n", i + 1, jobs.size(), jobs[i].input.string(),
               width, height, jobs[i].outputs[0].string(), width * args.scale, height * args.scale,
               pace.finished(i + 1));
    std::fflush(stdout);
  }
}

}  // namespace

void add_upscale_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "upscale", "Super-resolve an image, or every PNG / JPEG of a folder, with a 2D SR network");
  auto args = std::make_shared<UpscaleArgs>();
  std::string models;
  for (const std::string& name : priors::sr::sr_model_names())
    models += (models.empty() ? "" : ", ") + name;
  command->add_option("--model", args->model, "Backend: " + models)->required();
  command
      ->add_option("--weights", args->weights,
                   "Checkpoint (.pth), or package folder for esrgan-*; default for safmn, "
                   "imdn and pan <weights dir>/sr/<MODEL>_x<scale>.pth, the weights dir being "
                   "$IESRGS_WEIGHTS_DIR or the development data, for esrgan-* the npm package "
                   "setup installs; swinir needs one, bicubic takes none")
      ->check(CLI::ExistingPath);
  command->add_option("--scale", args->scale, "Upscaling factor")->capture_default_str();
  add_tile_options(*command, args->tiles);
  add_gray_background_option(*command, args->background);
  command->add_option("input", args->input, "Image or folder of images")->required();
  command
      ->add_option("output", args->output,
                   "PNG file, or a folder: for a folder input, or an existing one for an image")
      ->required()
      ->check(kNonEmptyPath);
  add_device_option(*command, args->device);
  command->callback([args] { run(*args); });
}

}  // namespace iesrgs::cli
