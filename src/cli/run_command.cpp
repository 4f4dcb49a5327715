// iesrgs run: the whole IE-SRGS pipeline with its baselines (and iesrgs internal / iesrgs fuse,
// the same options running one stage): external knowledge, internal model and SR-splatting,
// fusion training of the HR model, rendering and evaluation, each stage cached and resumable.

#include "cli/commands.hpp"
#include "cli/external_options.hpp"
#include "cli/scene_options.hpp"
#include "cli/shared_options.hpp"
#include "cli/validators.hpp"
#include "core/error.hpp"
#include "pipeline/ie_srgs.hpp"
#include "pipeline/rows.hpp"
#include "train/config.hpp"

namespace iesrgs::cli {

namespace {

struct TrainingArgs {
  std::string preset;
  int64_t iterations = 0;
  int views_per_iteration;
  std::vector<std::string> assignments;
  std::string option_prefix = "--";    // "--" or "--internal-": named in errors
  TrainingParameterOptions options{};  // the seed's is the command's, shared by both trainings

  train::TrainConfig resolve(uint64_t seed) const {
    train::TrainConfig config = train::make_preset(preset, iterations);
    config.views_per_iteration = views_per_iteration;
    config.seed = seed;
    for (const std::string& assignment : assignments)
      train::apply_assignment(config, assignment, option_prefix);
    train::validate(config);
    return config;
  }
};

struct RunArgs {
  SceneArgs scene;
  pipeline::RunOptions options;
  std::string output;
  TrainingArgs internal{"fast", 0, 3, {}};
  TrainingArgs fusion{"fast", 0, 1, {}};
  std::string texture = "masked";
  uint64_t seed = 0;
  std::string device = "auto";
};

// The HR rows' texture loss takes its D-SSIM weight from --dssim: the HR training config's own
// would go unused.
void refuse_unused_fusion_keys(const TrainingArgs& fusion) {
  for (const std::string& assignment : fusion.assignments)
    if (assignment.rfind("dssim_weight=", 0) == 0)
      fail("--set {}: the HR model's texture loss takes its D-SSIM weight from --dssim",
           assignment);
}

void run_pipeline(const RunArgs& args, pipeline::StageSelection only) {
  use_device(args.device);
  refuse_unused_fusion_keys(args.fusion);
  pipeline::RunOptions options = args.options;
  options.scene = args.scene.path;
  options.scene_options = args.scene.resolved();
  options.output = args.output;
  options.internal_config = args.internal.resolve(args.seed);
  options.fusion_config = args.fusion.resolve(args.seed);
  options.weights.texture = loss::parse_texture_guidance(args.texture);
  options.only = only;
  pipeline::run_ie_srgs(options);
}

void add_training_options(CLI::App& command, TrainingArgs& args, const std::string& stage,
                          const std::string& what) {
  const std::string prefix = stage.empty() ? "--" : "--" + stage + "-";
  command.add_option(prefix + "preset", args.preset, what + " schedule: paper, cpu, fast")
      ->capture_default_str();
  args.options.iterations =
      command
          .add_option(prefix + "iterations", args.iterations,
                      what + " iterations; the preset's schedule is rescaled to fit")
          ->check(kPositive);
  args.options.views_per_iteration =
      command
          .add_option(prefix + "mv", args.views_per_iteration,
                      what + " views per iteration (multi-view regulation K)")
          ->check(kPositive)
          ->capture_default_str();
  args.option_prefix = prefix;
  command.add_option(prefix + "set", args.assignments,
                     what + " training parameter key=value (repeatable; see config.json)");
}

// What the HR rows train with: stages 3 and 4, which `iesrgs internal` does not run.
void add_fusion_options(CLI::App& command, RunArgs& args) {
  pipeline::RunOptions& o = args.options;
  add_training_options(command, args.fusion, "", "HR model");
  command
      .add_option("--texture", args.texture,
                  "IE-SRGS texture guidance: masked, average, external or internal")
      ->capture_default_str();
  command.add_option("--li", o.weights.internal_depth, "Internal depth weight (0 = off)")
      ->capture_default_str()
      ->check(kNonNegative);
  command.add_option("--le", o.weights.external_depth, "External depth weight (0 = off)")
      ->capture_default_str()
      ->check(kNonNegative);
  command.add_option("--dssim", o.weights.dssim_weight, "D-SSIM weight l of the texture loss")
      ->capture_default_str()
      ->check(kUnitInterval);
  command
      .add_option(
          "--threshold", o.threshold,
          "Discrepancy threshold T (default 0.6 for NeRF Synthetic layouts, 0.9 for captures: "
          "COLMAP, transforms.json)")
      ->check(kNonNegative);
  command.add_option("--init", o.init, "HR model start: scene (as 3DGS) or internal")
      ->check(CLI::IsMember({"scene", "internal"}))
      ->capture_default_str();
  command
      .add_option("--rows", o.rows,
                  "Comparison rows, comma-separated: " + pipeline::describe_rows())
      ->delimiter(',')
      ->capture_default_str();
  add_lpips_option(command, o.lpips);
  command
      .add_option("--diagnostic-views", o.diagnostic_views,
                  "Training views in the diagnostics contact sheet")
      ->capture_default_str()
      ->check(kNonNegative);
}

void add_pipeline_command(CLI::App& app, const std::string& name, const std::string& description,
                          pipeline::StageSelection only) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* command = app.add_subcommand(name, description);
  args->scene.add_to(*command);
  command->get_option("--downscale")
      ->description(
          "HR ground truth at 1/k of the stored images, LR input at 1/(k*s): <images>_<k>/ "
          "when present, else a PIL-compatible bicubic resize");
  pipeline::RunOptions& o = args->options;
  command->add_option("-o,--output", args->output, "Run folder (stages, rows, results)")
      ->required()
      ->check(kNonEmptyPath);
  command->add_option("--scale", o.scale, "Super-resolution factor s")->capture_default_str();
  command->add_flag("--input-is-lr", o.input_is_lr,
                    "The scene's images are the LR input (no HR ground truth: render, no metrics)");
  add_training_options(*command, args->internal, "internal", "Internal (LR) model");
  const size_t internal_options = command->get_options().size();
  add_external_options(*command, o.external);
  add_fusion_options(*command, *args);
  // `iesrgs internal` takes the other stages' options too, so that one command line serves
  // every stage, but lists them apart as what they are there.
  if (only == pipeline::StageSelection::Internal) {
    const std::vector<CLI::Option*> options = command->get_options();
    for (size_t i = internal_options; i < options.size(); ++i)
      options[i]->group("Options of the other stages (accepted, unused here)");
  }
  CLI::Option* seed = command->add_option("--seed", args->seed, "Random seed of both trainings")
                          ->capture_default_str()
                          ->check(kNonNegative);
  add_device_option(*command, args->device);
  // Not listed: train's flag, which users carry over, answered with what to do instead.
  command
      ->add_flag_callback("--resume",
                          [name] {
                            fail(
                                "{} has no --resume: it resumes by itself; run the same command "
                                "without it",
                                name);
                          })
      ->group("");
  command->callback([args, only, seed] {
    for (TrainingArgs* training : {&args->internal, &args->fusion}) {
      training->options.seed = seed;
      refuse_sets_beside_options(training->options, training->assignments,
                                 training->option_prefix + "set");
    }
    run_pipeline(*args, only);
  });
}

}  // namespace

void add_run_command(CLI::App& app) {
  add_pipeline_command(
      app, "run", "IE-SRGS end to end: LR scene in, HR Gaussian scene, renders and metrics out",
      pipeline::StageSelection::All);
  add_pipeline_command(app, "internal",
                       "IE-SRGS stage 2 alone: the LR model and its SR-splatting renders",
                       pipeline::StageSelection::Internal);
  add_pipeline_command(app, "fuse",
                       "IE-SRGS stage 3 and 4 alone, from the cached external and internal stages",
                       pipeline::StageSelection::Fusion);
}

}  // namespace iesrgs::cli
