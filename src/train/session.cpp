#include "train/session.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>
#include <optional>

#include "core/error.hpp"
#include "core/math.hpp"
#include "io/atomic_file.hpp"
#include "io/image_tensor.hpp"
#include "io/model_file.hpp"
#include "io/ply.hpp"

namespace iesrgs::train {

namespace {

// 3DGS's random start for NeRF Synthetic scenes, whose objects fit in [-1.3, 1.3]^3.
constexpr double kNerfSyntheticHalfExtent = 1.3;

}  // namespace

std::vector<TrainView> load_views(const Scene& scene, Split split, ViewImages& images,
                                  size_t limit) {
  const std::vector<const Camera*> cameras = scene.split(split);
  std::vector<TrainView> views;
  for (size_t i : evenly_spaced(cameras.size(), limit == 0 ? cameras.size() : limit))
    views.push_back({*cameras[i], to_tensor(*images.rgb(*cameras[i]))[0]});
  return views;
}

TrainerSetup scene_setup(const Scene& scene, ViewImages& images, size_t test_views,
                         const std::filesystem::path& output_dir) {
  require_trainable_views(scene);
  TrainerSetup setup;
  setup.train_views = load_views(scene, Split::Train, images);
  setup.test_views = load_views(scene, Split::Test, images, test_views);
  setup.background = scene.background;
  setup.scene_extent = scene.normalization().radius;
  setup.output_dir = output_dir;
  return setup;
}

RandomBox random_box(const Scene& scene, const TrainConfig& config) {
  if (config.random_extent > 0) return {Vec3{}, config.random_extent};
  if (scene.synthetic) return {Vec3{}, kNerfSyntheticHalfExtent};
  const std::vector<const Camera*> cameras = scene.split(Split::Train);
  if (cameras.empty()) fail_file(scene.root, "no training cameras to place random points around");
  const std::optional<Vec3> focus = focus_point(cameras);
  if (!focus) {
    const SceneNormalization sphere = scene.normalization();
    return {sphere.center, sphere.radius};
  }
  double nearest = std::numeric_limits<double>::max();
  for (const Camera* camera : cameras)
    nearest = std::min(nearest, (camera->center() - *focus).norm());
  return {*focus, nearest};
}

gs::GaussianModel initial_model(const Scene& scene, const TrainConfig& config,
                                const std::filesystem::path& init_ply) {
  if (!init_ply.empty()) {
    spdlog::info("starting from {}", init_ply.string());
    const SplatCloud cloud = read_model(init_ply);
    if (cloud.size() == 0) fail_file(init_ply, "has no Gaussians to start training from");
    return gs::model_from_splat_cloud(cloud);
  }
  if (config.init == "auto" && !scene.points.positions.empty()) {
    spdlog::info("starting from {} SfM points", scene.points.positions.size());
    return gs::model_from_point_cloud(scene.points);
  }
  require_training_memory(config.random_points, compute_device());
  const RandomBox box = random_box(scene, config);
  spdlog::info(
      "starting from {} random points in the cube of half-size {:.3g} around ({:.3g}, "
      "{:.3g}, {:.3g})",
      config.random_points, box.half_extent, box.center.x, box.center.y, box.center.z);
  return gs::model_from_random_box(config.random_points, float(box.half_extent), config.seed,
                                   box.center);
}

void write_point_clouds(const std::filesystem::path& dir, const Trainer& trainer) {
  SplatCloud cloud = gs::to_splat_cloud(trainer.model());
  cloud.background = trainer.background();
  write_ply_filter_baked(dir / "point_cloud_filter_baked.ply", cloud);
  write_ply(model_path(dir), cloud);
}

bool remove_earlier_run(const std::filesystem::path& dir) {
  bool removed = false;
  for (const std::filesystem::path& file :
       {checkpoint_path(dir), dir / "train_log.csv", dir / "cameras.json", dir / "training.json",
        model_path(dir), dir / "point_cloud_filter_baked.ply"})
    removed |= remove_earlier_output(file, "left by an earlier run");
  return removed;
}

std::filesystem::path trained_model_file(const std::filesystem::path& path) {
  if (!std::filesystem::is_directory(path)) return path;
  const std::filesystem::path model = model_path(path);
  if (!std::filesystem::exists(model)) {
    // A run's stage folder is trained by the command that made it, not by train.
    const bool stage = std::filesystem::exists(path / "stage.json");
    constexpr const char* kRunCommand = "the iesrgs run, internal or fuse command that made it";
    if (std::filesystem::exists(checkpoint_path(path)))
      fail_file(path, fmt::format("its training has not finished (a checkpoint, no "
                                  "point_cloud.ply yet): {}",
                                  stage ? fmt::format("{} continues it", kRunCommand)
                                        : "the same train command with --resume continues it"));
    if (std::filesystem::exists(path / "train_log.csv"))
      fail_file(path, fmt::format("its training stopped before its first checkpoint, so it holds "
                                  "no model yet: {}",
                                  stage ? fmt::format("{} trains it", kRunCommand)
                                        : "train it again (--resume has nothing to continue)"));
  }
  if (!std::filesystem::exists(model) && is_run_folder(path)) {
    const std::vector<std::filesystem::path> models = run_folder_models(path);
    fail_file(path, models.empty() ? std::string("a run folder of iesrgs run, with no model yet")
                                   : fmt::format("a run folder of iesrgs run, which holds a model "
                                                 "per row: name one, e.g. {} (iesrgs info lists "
                                                 "them)",
                                                 models.front().parent_path().string()));
  }
  return model;
}

bool is_training_folder(const std::filesystem::path& dir) {
  return std::filesystem::exists(model_path(dir)) ||
         std::filesystem::exists(checkpoint_path(dir)) ||
         std::filesystem::exists(dir / "train_log.csv");
}

bool is_run_folder(const std::filesystem::path& dir) {
  return std::filesystem::is_directory(dir / "rows") ||
         std::filesystem::exists(dir / "internal" / "stage.json");
}

std::vector<std::filesystem::path> run_folder_models(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> models;
  if (std::filesystem::is_directory(dir / "rows"))
    for (const auto& row : std::filesystem::directory_iterator(dir / "rows"))
      if (std::filesystem::exists(model_path(row.path()))) models.push_back(model_path(row.path()));
  if (std::filesystem::exists(model_path(dir / "internal")))
    models.push_back(model_path(dir / "internal"));
  std::sort(models.begin(), models.end());
  return models;
}

}  // namespace iesrgs::train
