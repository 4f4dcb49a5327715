// iesrgs depth: monocular relative depth (inverse depth) for one image or a folder of them.
#include <fmt/format.h>

#include <memory>
#include <string>

#include "cli/commands.hpp"
#include "cli/shared_options.hpp"
#include "cli/validators.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"
#include "io/image.hpp"
#include "io/image_jobs.hpp"
#include "io/image_tensor.hpp"
#include "priors/depth/depth_files.hpp"
#include "priors/depth/depth_net.hpp"

namespace iesrgs::cli {

namespace {

struct DepthArgs {
  std::string model = "depth-anything-v2";
  std::string weights, in, out;
  float background = 0.f;
  std::string device = "auto";
};

void run_depth(const DepthArgs& args) {
  using priors::depth::DepthJob;
  use_device(args.device);
  const std::vector<DepthJob> jobs = priors::depth::plan_depth_jobs(args.in, args.out);
  const auto lock = lock_results_folder(args.in, args.out);
  const std::unique_ptr<priors::depth::DepthNet> net =
      priors::depth::make_depth_net(args.model, args.weights);
  if (!net) fail("depth: model '{}' predicts nothing, so there is nothing to write", args.model);
  const float background[3] = {args.background, args.background, args.background};
  ItemPace pace(jobs.size());
  for (size_t i = 0; i < jobs.size(); ++i) {
    const Image rgb = composite_rgb(read_image8(jobs[i].image), background);
    priors::depth::write_depth_outputs(net->predict(to_tensor(rgb)), jobs[i]);
    fmt::print("[{}/{}] {} -> {} ({}x{}, {})\n", i + 1, jobs.size(), jobs[i].image.string(),
               jobs[i].npy.string(), rgb.width, rgb.height, pace.finished(i + 1));
  }
}

}  // namespace

void add_depth_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "depth",
      "Predict relative inverse depth for an image or a folder of PNG / JPEG images: a float32 "
      ".npy of the raw values and a false-color preview PNG (<name>_preview.png) per image");
  auto args = std::make_shared<DepthArgs>();
  command
      ->add_option("--model", args->model,
                   "depth-anything-v2-vits, -vitb, -vitl, or depth-anything-v2 to take the "
                   "encoder from the checkpoint")
      ->capture_default_str();
  command
      ->add_option("--weights", args->weights,
                   "The authors' checkpoint, depth_anything_v2_<vits|vitb|vitl>.pth")
      ->required();
  add_gray_background_option(*command, args->background);
  command->add_option("IN", args->in, "An image, or a folder of images")->required();
  command
      ->add_option("OUT", args->out,
                   "For an image: the .npy to write, or an existing folder to write it into; for a "
                   "folder: the folder to write into")
      ->required()
      ->check(kNonEmptyPath);
  add_device_option(*command, args->device);
  command->callback([args] { run_depth(*args); });
}

}  // namespace iesrgs::cli
