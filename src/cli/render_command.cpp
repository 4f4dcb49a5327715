// iesrgs render: a trained model seen from a scene's cameras, at any resolution factor
// (--scale 4 renders four times the cameras' resolution with the same field of view), or along a
// camera path made from the training cameras (--path orbit | interp).
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/scene_options.hpp"
#include "cli/shared_options.hpp"
#include "cli/validators.hpp"
#include "core/device.hpp"
#include "core/error.hpp"
#include "gs/model.hpp"
#include "io/folder_lock.hpp"
#include "io/model_file.hpp"
#include "pipeline/camera_path.hpp"
#include "pipeline/render_views.hpp"
#include "train/session.hpp"

namespace iesrgs::cli {

namespace {

// An hour at 30 frames per second; every frame's camera is made before the first renders.
constexpr int kMostFrames = 108000;

struct RenderArgs {
  std::string model;
  SceneArgs scene;
  std::string output;
  std::string split = "test";
  double scale = 1;
  std::string path;
  int frames = 120;
  std::string rasterize_mode = "auto";
  std::string device = "auto";
};

// Checked before scaling, which rounds to int: a side beyond 2^16 is no render anyone can store.
// Every view, since a scene's cameras may differ in size.
void require_render_sizes(const std::vector<Camera>& cameras, double scale,
                          const std::filesystem::path& scene) {
  for (const Camera& camera : cameras) {
    const double width = camera.intrinsics.width * scale, height = camera.intrinsics.height * scale;
    if (std::min(width, height) < 0.5 || std::max(width, height) > 65536)
      fail_file(scene, fmt::format("--scale {}: view {} would be {:.0f}x{:.0f} pixels (1 to 65536 "
                                   "a side)",
                                   scale, camera.name, width, height));
  }
}

void run_render(const RenderArgs& args) {
  use_device(args.device);
  const SplatCloud cloud = read_model(train::trained_model_file(args.model));
  gs::GaussianModel model = gs::model_from_splat_cloud(cloud).to(compute_device());
  if (args.rasterize_mode != "auto") model.antialiased = args.rasterize_mode == "antialiased";
  SceneOptions scene_options = args.scene.resolved();
  // As 3DGS renders: over the background the model was trained over, where it is known.
  if (!scene_options.background) scene_options.background = cloud.background;
  const Scene scene = load_scene(args.scene.path, scene_options);
  const std::string what = args.path.empty() ? args.split : args.path + " path";
  std::vector<Camera> cameras;
  if (args.path.empty()) {
    for (const Camera* camera : scene.split(args.split == "train" ? Split::Train : Split::Test))
      cameras.push_back(*camera);
  } else {
    const std::vector<const Camera*> train = scene.split(Split::Train);
    if (train.empty()) fail_file(scene.root, "has no training views to fit a camera path to");
    try {
      cameras = args.path == "orbit" ? pipeline::orbit_path(train, args.frames)
                                     : pipeline::interpolated_path(train, args.frames);
    } catch (const Error& e) {
      fail_file(scene.root, e.what());  // the path cannot be fitted to this scene's cameras
    }
  }
  if (cameras.empty()) fail_file(scene.root, fmt::format("has no {} views", args.split));
  require_render_sizes(cameras, args.scale, scene.root);
  refuse_output_in_scene_folder(args.output, scene);
  // Two renders into one folder would leave a mix of two models' views.
  const FolderLock lock(args.output);
  const char* mode = model.antialiased ? "antialiased" : "classic";
  fmt::print("rendering {} {} views of {} Gaussians at x{} ({}, background {})\n", cameras.size(),
             what, model.size(), args.scale, mode, fmt::join(scene.background, ","));
  // What eval checks its ground truth against.
  const nlohmann::json record =
      args.path.empty()
          ? nlohmann::json{{"split", args.split}, {"test_every", scene_options.test_every}}
          : nlohmann::json{{"path", args.path}};
  const double seconds = pipeline::render_views_recorded(args.output, model, cameras,
                                                         scene.background, args.scale, record);
  fmt::print("{:.1f} ms per view ({:.1f} FPS); wrote {}\n", seconds * 1e3,
             pipeline::frames_per_second(seconds), args.output);
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* command = app.add_subcommand("render", "Render a trained model from a scene's cameras");
  command
      ->add_option("model", args->model, "Training output folder, a 3DGS .ply, an .spz or a .splat")
      ->required();
  args->scene.add_to(*command);
  command->get_option("--background")
      ->description(
          "Background behind the model: white, black, r,g,b in [0,1], or auto (the one the model "
          "was trained over, which a .ply of iesrgs records, else white for NeRF Synthetic "
          "scenes and black for captures, as 3DGS)");
  command->add_option("-o,--output", args->output, "Output folder (rgb/, depth/, alpha/)")
      ->required()
      ->check(kNonEmptyPath);
  command->add_option("--split", args->split, "Which cameras")
      ->check(CLI::IsMember({"train", "test"}))
      ->capture_default_str();
  command->add_option("--scale", args->scale, "Resolution factor over the cameras' (SR-splatting)")
      ->check(kPositive)
      ->capture_default_str();
  command
      ->add_option("--path", args->path,
                   "Render a camera path instead of --split (frames path_0000.png, ...): orbit, "
                   "fitted to the training cameras (or a sweep along the arc they cover) and "
                   "looking at the point they look at; interp, a smooth curve through the "
                   "training cameras in order")
      ->check(CLI::IsMember({"orbit", "interp"}));
  command->add_option("--frames", args->frames, "Frames of --path")
      ->check(CLI::Range(1, kMostFrames))
      ->capture_default_str();
  command
      ->add_option("--rasterize-mode", args->rasterize_mode,
                   "2D filter: antialiased (Mip-Splatting's), classic (3DGS's dilation) or auto, "
                   "the model's own (antialiased with a filter_3D or an .spz flagged so)")
      ->check(CLI::IsMember({"auto", "antialiased", "classic"}))
      ->capture_default_str();
  add_device_option(*command, args->device);
  command->callback([args] { run_render(*args); });
}

}  // namespace iesrgs::cli
