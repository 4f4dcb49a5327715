// iesrgs train: fits a Mip-Splatting model to a scene's training views and writes the standard
// 3DGS point cloud, the config used and a summary.
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include <optional>

#include "cli/commands.hpp"
#include "cli/scene_options.hpp"
#include "cli/shared_options.hpp"
#include "cli/validators.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/memory.hpp"
#include "io/atomic_file.hpp"
#include "io/folder_lock.hpp"
#include "io/json_file.hpp"
#include "train/session.hpp"

namespace iesrgs::cli {

namespace {

struct TrainArgs {
  SceneArgs scene;
  std::string output;
  std::string preset = "cpu";
  int64_t iterations = 0;
  int views_per_iteration = 0;
  int64_t seed = -1;
  std::string config_file;
  std::vector<std::string> assignments;
  std::string init_ply;
  bool resume = false;
  bool run_options_given = false;  // any of those that make up the config
  bool preset_given = false;
  std::string device = "auto";
};

// The config a new run with these options trains with. With `base` and no --preset, the options
// apply to `base` instead, --iterations rescaling its schedule.
train::TrainConfig requested_config(const TrainArgs& args,
                                    const std::optional<train::TrainConfig>& base = std::nullopt) {
  train::TrainConfig config =
      base && !args.preset_given ? *base : train::make_preset(args.preset, args.iterations);
  if (base && !args.preset_given && args.iterations > 0)
    train::rescale_schedule(config, args.iterations);
  if (!args.config_file.empty()) {
    const nlohmann::json file = read_json_file(args.config_file);
    // The preset names where the schedule came from: a file's own would relabel this one's.
    if (file.is_object() && file.contains("preset") && file["preset"] != config.preset)
      fail_file(args.config_file,
                fmt::format("its preset {} is not this run's \"{}\": the preset is chosen with "
                            "--preset, which also sets its schedule",
                            file["preset"].dump(), config.preset));
    train::apply_json(config, file, args.config_file);
  }
  if (args.views_per_iteration > 0) config.views_per_iteration = args.views_per_iteration;
  if (args.seed >= 0) config.seed = uint64_t(args.seed);
  for (const std::string& assignment : args.assignments)
    train::apply_assignment(config, assignment);
  train::validate(config);
  return config;
}

// The stored config is the run's identity: --resume continues with it. Options given beside it
// must make the same config (the run's own command again) but for its reporting fields
// (train::kReportingFields), which they may change, or none be given. Without --preset they apply
// to the stored config, so that the refusal names only what they change.
train::TrainConfig resumed_config(const TrainArgs& args, const std::filesystem::path& saved) {
  if (!std::filesystem::exists(saved))
    fail_file(saved, "missing: --resume needs the output folder of an earlier run");
  train::TrainConfig config;
  train::apply_json(config, read_json_file(saved), saved.string());
  try {
    train::validate(config);  // an edited file: the error names it
  } catch (const Error& e) {
    fail_file(saved, e.what());
  }
  spdlog::info("resuming with the config saved in {}", saved.string());
  if (!args.run_options_given) return config;
  const train::TrainConfig requested = requested_config(args, config);
  const std::vector<std::string> changes = train::config_changes(config, requested);
  if (!changes.empty())
    fail_file(saved, fmt::format(
                         "--resume continues this run, and the options given would change it ({}); "
                         "give the run's own options or none, or train into a new folder",
                         fmt::join(changes, ", ")));
  return requested;
}

void run_train(const TrainArgs& args) {
  use_device(args.device);
  const std::filesystem::path out = args.output;
  const train::TrainConfig config =
      args.resume ? resumed_config(args, out / "config.json") : requested_config(args);

  const Scene scene = load_scene(args.scene.path, args.scene.resolved());
  ViewImages images(scene);
  train::TrainerSetup setup = train::scene_setup(scene, images, size_t(config.test_views), out);
  refuse_output_in_scene_folder(out, scene);
  // Once the scene has loaded, so that a refused input leaves no folder behind.
  const FolderLock lock(out);
  const int width = setup.train_views.front().camera.intrinsics.width;
  const int height = setup.train_views.front().camera.intrinsics.height;
  fmt::print("training on {} views ({}x{}), {} test views; preset {}, {} iterations, K = {}\n",
             setup.train_views.size(), width, height, setup.test_views.size(), config.preset,
             config.iterations, setup.views_per_step(config));

  train::Trainer trainer = args.resume
                               ? train::Trainer::resumed(config, std::move(setup))
                               : train::Trainer(config, std::move(setup),
                                                train::initial_model(scene, config, args.init_ply));
  if (args.resume)
    fmt::print("resuming {} from {}\n", trainer.resume_point(), trainer.checkpoint_path().string());
  // Only now that the scene and the starting model have loaded: a folder holding a config but no
  // checkpoint would make --resume fail on that instead of the real problem.
  if (!args.resume && train::remove_earlier_run(out))
    spdlog::warn("{}: replaced the earlier run there (--resume continues a run instead)",
                 out.string());
  // Again on --resume: it may report and checkpoint otherwise.
  write_file_atomically(out / "config.json", train::to_json(config).dump(2) + "\n");
  // Across the model's files after training too: a stop asked for while they are written lets
  // them finish (training's own scope would otherwise give the signal back to end_now).
  const InterruptScope finishing;
  const train::TrainSummary summary = trainer.run();
  if (summary.interrupted) throw Interrupted("continue with the same command and --resume");
  train::write_point_clouds(out, trainer);

  const nlohmann::json report = {
      {"scene", scene.root.string()},
      {"downscale", scene.downscale},
      {"width", width},
      {"height", height},
      {"iterations", summary.iterations},
      {"seconds", summary.seconds},
      {"iterations_per_second", summary.iterations_per_second},
      {"gaussians", summary.gaussians},
      {"final_loss", summary.final_loss},
      {"test_psnr", summary.test_psnr ? nlohmann::json(*summary.test_psnr) : nlohmann::json()},
      {"peak_memory_mib", double(peak_memory_bytes()) / (1 << 20)}};
  write_file_atomically(out / "training.json", report.dump(2) + "\n");
  fmt::print("done: {} Gaussians, {:.2f} it/s, {}; wrote {}\n", summary.gaussians,
             summary.iterations_per_second,
             summary.test_psnr ? fmt::format("test PSNR {:.2f} dB", *summary.test_psnr)
                               : std::string("no test views scored"),
             train::model_path(out).string());
}

}  // namespace

void add_train_command(CLI::App& app) {
  auto args = std::make_shared<TrainArgs>();
  CLI::App* command = app.add_subcommand("train", "Train a Gaussian-splatting model on a scene");
  args->scene.add_to(*command);
  command->add_option("-o,--output", args->output, "Output folder")
      ->required()
      ->check(kNonEmptyPath);
  // The options that make up the run's config, which --resume takes from the output folder.
  std::vector<const CLI::Option*> run_options;
  const auto defines_run = [&run_options](CLI::Option* option) {
    run_options.push_back(option);
    return option;
  };
  CLI::Option* preset = defines_run(command->add_option(
      "--preset", args->preset, "Schedule: paper (30k, GPU), cpu (10k), fast (3k)"));
  preset->capture_default_str();
  CLI::Option* iterations = defines_run(command->add_option(
      "--iterations", args->iterations, "Iterations; the preset's schedule is rescaled to fit"));
  iterations->check(kPositive);
  CLI::Option* mv = defines_run(
      command->add_option("--mv", args->views_per_iteration,
                          "Views per iteration (multi-view regulation K; 1 = plain 3DGS)"));
  mv->check(kPositive);
  CLI::Option* seed = defines_run(command->add_option("--seed", args->seed, "Random seed"));
  seed->check(kNonNegative);
  defines_run(
      command->add_option("--config", args->config_file, "JSON file of training parameters"));
  defines_run(command->add_option(
      "--set", args->assignments,
      "Override one training parameter, key=value (repeatable; see config.json)"));
  // Not part of the config: a resumed run starts from its checkpoint whatever it says.
  command->add_option("--init-ply", args->init_ply,
                      "Start from this 3DGS .ply, .spz or .splat instead");
  command->add_flag("--resume", args->resume,
                    "Continue the run in --output from its checkpoint, with its saved config");
  add_device_option(*command, args->device);
  command->callback([args, run_options, preset, iterations, mv, seed] {
    refuse_sets_beside_options({iterations, mv, seed}, args->assignments, "--set");
    for (const CLI::Option* option : run_options) args->run_options_given |= option->count() > 0;
    args->preset_given = preset->count() > 0;
    run_train(*args);
  });
}

}  // namespace iesrgs::cli
