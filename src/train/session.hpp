#pragma once
// A scene on disk turned into what the trainer takes, and the trained model turned into the
// standard outputs.
#include <filesystem>
#include <vector>

#include "gs/model.hpp"
#include "io/scene.hpp"
#include "io/view_images.hpp"
#include "train/config.hpp"
#include "train/trainer.hpp"

namespace iesrgs::train {

// The cameras of `split` with their decoded images, in scene order: all of them, or `limit`
// evenly spaced ones when limit is positive and smaller (the periodic test report needs few).
std::vector<TrainView> load_views(const Scene& scene, Split split, ViewImages& images,
                                  size_t limit = 0);

// Training on `scene`'s training views, reporting PSNR on `test_views` evenly spaced test views
// (0: all), with checkpoints and logs in output_dir.
TrainerSetup scene_setup(const Scene& scene, ViewImages& images, size_t test_views,
                         const std::filesystem::path& output_dir);

// Where random starting points go: the cube of half-size `half_extent` around `center`.
struct RandomBox {
  Vec3 center;
  double half_extent = 0;
};

// config.random_extent around the origin when it is positive. Otherwise (0, the default): for
// NeRF Synthetic scenes 3DGS's cube of half-size 1.3 around the origin; for other scenes the cube
// around what the training cameras look at (their focus point) that reaches the nearest of them,
// or, when their axes are parallel, the cube around the scene's normalization sphere.
RandomBox random_box(const Scene& scene, const TrainConfig& config);

// The starting model: `init_ply` when given, else SfM points when the scene has them and the
// config allows, else config.random_points in random_box.
gs::GaussianModel initial_model(const Scene& scene, const TrainConfig& config,
                                const std::filesystem::path& init_ply);

// <dir>/point_cloud.ply (3DGS layout plus the Mip-Splatting filter_3D property) and
// <dir>/point_cloud_filter_baked.ply (the filter folded into scale and opacity, for viewers that
// do not know it), both written atomically, of the trainer's model and with the background it
// trains over; the model last, since it tells a finished training (a process killed between the
// two leaves a training to resume).
void write_point_clouds(const std::filesystem::path& dir, const Trainer& trainer);

// Removes what an earlier training left in `dir` (checkpoint, log, point clouds, summary), before
// a new run there: --resume would otherwise continue the earlier checkpoint under the new
// config, and a render draw the earlier model. Returns whether there was anything to remove.
bool remove_earlier_run(const std::filesystem::path& dir);

// A trained model given as its training folder (its point_cloud.ply) or as a model file. Throws
// Error for a folder whose training has not finished, and for a run folder of iesrgs run.
std::filesystem::path trained_model_file(const std::filesystem::path& path);

// A folder a training wrote into: its model, its checkpoint, or the log of one stopped before
// its first checkpoint.
bool is_training_folder(const std::filesystem::path& dir);

// A run folder of iesrgs run (or of iesrgs internal alone): rows/, or the internal stage.
bool is_run_folder(const std::filesystem::path& dir);

// The trained models in a run folder, each row's (rows/<row>/) and the internal model, sorted.
std::vector<std::filesystem::path> run_folder_models(const std::filesystem::path& dir);

}  // namespace iesrgs::train
