// iesrgs info: what a scene holds, and with --load-images whether every image decodes; what
// a trained model (.ply) holds; or what a run folder of iesrgs run scored.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "cli/commands.hpp"
#include "cli/scene_options.hpp"
#include "core/math.hpp"
#include "core/progress.hpp"
#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "io/scene.hpp"
#include "io/view_images.hpp"
#include "train/session.hpp"

namespace iesrgs::cli {

namespace {

void print_summary(const Scene& scene) {
  fmt::print("scene       {}\n", scene.root.string());
  fmt::print("format      {}\n", scene.format);
  fmt::print("cameras     {} ({} train, {} test)\n", scene.cameras.size(),
             scene.split(Split::Train).size(), scene.split(Split::Test).size());
  std::map<std::pair<int, int>, int> sizes;
  int distorted = 0;
  for (const Camera& camera : scene.cameras) {
    ++sizes[{camera.intrinsics.width, camera.intrinsics.height}];
    distorted += camera.distortion.any();
  }
  for (const auto& [size, count] : sizes)
    fmt::print("image size  {}x{} ({} cameras{})\n", size.first, size.second, count,
               scene.downscale > 1 ? fmt::format(", downscaled by {}", scene.downscale) : "");
  const Intrinsics& k = scene.cameras.front().intrinsics;
  fmt::print("intrinsics  fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f} (fov {:.2f} x {:.2f} deg)\n",
             k.fx, k.fy, k.cx, k.cy, k.fov_x() * 180 / kPi, k.fov_y() * 180 / kPi);
  if (distorted)
    fmt::print(
        "distortion  {} cameras, undistorted when loaded (the intrinsics above are the first "
        "camera's after it)\n",
        distorted);
  fmt::print("points      {}\n", scene.points.positions.size());
  if (scene.points.positions.empty() && !scene.split(Split::Train).empty()) {
    const train::RandomBox box = train::random_box(scene, train::TrainConfig{});
    fmt::print(
        "start       random points in the cube of half-size {:.3f} around ({:.3f}, {:.3f}, "
        "{:.3f})\n",
        box.half_extent, box.center.x, box.center.y, box.center.z);
  }
  const SceneNormalization norm = scene.normalization();
  fmt::print("extent      center ({:.3f}, {:.3f}, {:.3f}) radius {:.3f}\n", norm.center.x,
             norm.center.y, norm.center.z, norm.radius);
  for (const std::string& warning : camera_warnings(scene)) fmt::print("warning     {}\n", warning);
  fmt::print("background  {:.3g} {:.3g} {:.3g}\n", scene.background[0], scene.background[1],
             scene.background[2]);
}

void print_model_summary(const std::filesystem::path& path) {
  const SplatCloud cloud = read_model(path);
  const size_t n = cloud.size();
  fmt::print("model       {}\n", path.string());
  fmt::print("gaussians   {}\n", n);
  fmt::print("sh degree   {}\n", cloud.sh_degree);
  fmt::print("3D filter   {}\n", cloud.has_filter_3d() ? "yes (Mip-Splatting)" : "no");
  fmt::print("2D filter   {}\n",
             cloud.antialiased ? "Mip-Splatting's (antialiased)" : "3DGS's dilation (classic)");
  if (const auto& background = cloud.background)
    fmt::print("background  {:.3g} {:.3g} {:.3g} (trained over)\n", (*background)[0],
               (*background)[1], (*background)[2]);
  if (n == 0) return;
  Vec3 low{INFINITY, INFINITY, INFINITY}, high = -low;
  std::vector<double> opacity(n), largest_scale(n);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &cloud.positions[3 * i];
    low = {std::min(low.x, double(p[0])), std::min(low.y, double(p[1])),
           std::min(low.z, double(p[2]))};
    high = {std::max(high.x, double(p[0])), std::max(high.y, double(p[1])),
            std::max(high.z, double(p[2]))};
    opacity[i] = sigmoid(cloud.opacity[i]);
    const float* s = &cloud.log_scales[3 * i];
    largest_scale[i] = std::exp(double(std::max({s[0], s[1], s[2]})));
  }
  fmt::print("bounds      ({:.3f}, {:.3f}, {:.3f}) to ({:.3f}, {:.3f}, {:.3f})\n", low.x, low.y,
             low.z, high.x, high.y, high.z);
  fmt::print("opacity     median {:.3f}\n", median(opacity));
  fmt::print("scale       median largest axis {:.4g}\n", median(largest_scale));
}

// A run folder of iesrgs run: its results table (once the run has finished) and each trained
// row's model, the internal row's being the internal model.
void print_run_summary(const std::filesystem::path& run) {
  const std::filesystem::path table = run / "results.md";
  if (std::filesystem::exists(table))
    fmt::print("{}", read_file(table));  // ends in a newline
  else
    fmt::print("no results.md yet: the run has not finished\n");
  for (const std::filesystem::path& model : train::run_folder_models(run))
    fmt::print("model of {:<16} {}\n", model.parent_path().filename().string(), model.string());
}

// Decodes every image in order and stops at the first bad one (the Error names it).
void load_every_image(const Scene& scene) {
  ViewImageOptions options;
  options.cache_bytes = 0;  // stream: one image in memory at a time
  ViewImages images(scene, options);
  size_t done = 0;
  for (const Camera& camera : scene.cameras) {
    images.rgb(camera);
    ++done;
    if (done % 25 == 0 || done == scene.cameras.size())
      print_count_on_stderr("decoded images", done, scene.cameras.size());
  }
  fmt::print("images      all {} decoded\n", done);
}

}  // namespace

void add_info_command(CLI::App& app) {
  auto* command =
      app.add_subcommand("info",
                         "Print a scene's cameras, image size, splits, points and extent, a "
                         "trained model's (training folder, .ply, .spz, .splat) Gaussians, or a "
                         "run folder's results");
  auto args = std::make_shared<SceneArgs>();
  auto load_images = std::make_shared<bool>(false);
  args->add_to(*command, std::string(SceneArgs::kSceneHelp) +
                             "; or a model (a training folder, .ply, .spz, .splat) or a run "
                             "folder of iesrgs run");
  command->add_flag("--load-images", *load_images,
                    "Also decode every image (undistorted and resized as training would) and "
                    "fail on the first bad one");
  command->callback([args, load_images] {
    const std::filesystem::path path = args->path;
    if (is_model_file(path) || (!is_scene(path) && train::is_training_folder(path))) {
      print_model_summary(train::trained_model_file(path));
      return;
    }
    if (!is_scene(path) && train::is_run_folder(path)) {
      print_run_summary(path);
      return;
    }
    const Scene scene = load_scene(args->path, args->resolved());
    print_summary(scene);
    if (*load_images) load_every_image(scene);
  });
}

}  // namespace iesrgs::cli
