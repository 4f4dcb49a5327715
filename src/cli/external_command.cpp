// iesrgs external: stage 1 of IE-SRGS alone (2D super-resolution and monocular depth of every
// training view), cached and resumable.
#include "cli/commands.hpp"
#include "cli/scene_options.hpp"
#include "pipeline/external_stage.hpp"

namespace iesrgs::cli {

namespace {

struct ExternalArgs {
  SceneArgs scene;
  std::string output;
  pipeline::ExternalOptions options;
};

void run_external(const ExternalArgs& args) {
  const Scene scene = load_scene(args.scene.path, args.scene.resolved());
  ViewImages images(scene);
  pipeline::run_external_stage(scene, images, args.options, args.output);
}

}  // namespace

void add_external_command(CLI::App& app) {
  auto args = std::make_shared<ExternalArgs>();
  CLI::App* command = app.add_subcommand(
      "external", "External knowledge: super-resolve (and estimate depth of) every training view");
  args->scene.add_to(*command);
  command->add_option("-o,--output", args->output, "Output folder (image/, depth/)")->required();
  pipeline::ExternalOptions& o = args->options;
  command->add_option("--sr-model", o.sr_model, "2D SR backend (see iesrgs upscale)")
      ->capture_default_str();
  command->add_option("--sr-weights", o.sr_weights, "SR checkpoint (default: the model's own)");
  command->add_option("--scale", o.scale, "Upscaling factor s")->capture_default_str();
  command->add_option("--tile", o.tiles.tile, "SR tile side in input pixels, 0 = whole image")
      ->capture_default_str();
  command
      ->add_option("--depth-model", o.depth_model,
                   "none, or depth-anything-v2[-vits|-vitb|-vitl] (needs --depth-weights)")
      ->capture_default_str();
  command->add_option("--depth-weights", o.depth_weights, "Depth Anything V2 checkpoint");
  command->callback([args] { run_external(*args); });
}

}  // namespace iesrgs::cli
