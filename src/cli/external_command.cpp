// iesrgs external: stage 1 of IE-SRGS alone (2D super-resolution and monocular depth of every
// training view), cached and resumable.
#include "cli/commands.hpp"
#include "cli/external_options.hpp"
#include "cli/scene_options.hpp"
#include "cli/shared_options.hpp"
#include "cli/validators.hpp"
#include "io/folder_lock.hpp"
#include "pipeline/external_stage.hpp"

namespace iesrgs::cli {

namespace {

struct ExternalArgs {
  SceneArgs scene;
  std::string output;
  pipeline::ExternalOptions options;
  std::string device = "auto";
};

void run_external(const ExternalArgs& args) {
  use_device(args.device);
  const Scene scene = load_scene(args.scene.path, args.scene.resolved());
  ViewImages images(scene);
  pipeline::ExternalOptions options = args.options;
  pipeline::resolve_sr_model(options, true);
  refuse_output_in_scene_folder(args.output, scene);
  const FolderLock lock(args.output);
  pipeline::run_external_stage(scene, images, options, args.output);
}

}  // namespace

void add_external_command(CLI::App& app) {
  auto args = std::make_shared<ExternalArgs>();
  CLI::App* command = app.add_subcommand(
      "external", "External knowledge: super-resolve (and estimate depth of) every training view");
  args->scene.add_to(*command);
  command->add_option("-o,--output", args->output, "Output folder (image/, depth/)")
      ->required()
      ->check(kNonEmptyPath);
  command->add_option("--scale", args->options.scale, "Upscaling factor s")->capture_default_str();
  add_external_options(*command, args->options);
  add_device_option(*command, args->device);
  command->callback([args] { run_external(*args); });
}

}  // namespace iesrgs::cli
