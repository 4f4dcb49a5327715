#pragma once
// The Gaussian-splatting training loop every stage uses: Mip-Splatting (3D filter, 2D mip
// filter) with 3DGS's densification and schedules, and MVGS's multi-view regulation (K distinct
// views per iteration, losses summed, one optimizer step, densification statistics from all K).
// It trains on the compute device (core/device.hpp) that is current when it is built.
#include <torch/types.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "core/device.hpp"
#include "core/stopwatch.hpp"
#include "gs/checkpoint.hpp"
#include "gs/model.hpp"
#include "io/camera.hpp"
#include "raster/autograd.hpp"
#include "train/config.hpp"

namespace iesrgs::train {

// A camera the model is fitted to, with its reference image (3, H, W) in [0, 1].
struct TrainView {
  Camera camera;
  torch::Tensor target;
};

// Loss of one rendered view; the default is (1 - w) * L1 + w * D-SSIM against the view's target.
using ViewLoss = std::function<torch::Tensor(int view, const raster::RenderOutput& render)>;

struct TrainerSetup {
  std::vector<TrainView> train_views;
  // For the periodic PSNR report, every one scored (load_views picks config.test_views of the
  // split); may be empty.
  std::vector<TrainView> test_views;
  std::array<float, 3> background{1, 1, 1};
  double scene_extent = 1;
  std::filesystem::path output_dir;  // checkpoint.pt, train_log.csv, cameras.json go here
  ViewLoss loss;                     // empty: the photometric default

  // K as an iteration applies it: distinct views, so at most every training view.
  size_t views_per_step(const TrainConfig& config) const {
    return std::min(train_views.size(), size_t(config.views_per_iteration));
  }
};

// Fails up front when training `gaussians` Gaussians would not fit in the available memory of
// `device`.
void require_training_memory(int64_t gaussians, torch::Device device);

struct TrainSummary {
  int64_t iterations = 0;            // completed in total (including before a resume)
  bool interrupted = false;          // stopped by SIGINT or SIGTERM after saving a checkpoint
  double seconds = 0;                // of training, the runs before a resume included
  double iterations_per_second = 0;  // iterations / seconds
  double final_loss = 0;
  std::optional<double> test_psnr;  // the last report; none without test views or reports
  int64_t gaussians = 0;
};

// Where a trainer writing to `output_dir` keeps its checkpoint.
inline std::filesystem::path checkpoint_path(const std::filesystem::path& output_dir) {
  return output_dir / "checkpoint.pt";
}

// The finished model in a training folder: the 3DGS point cloud viewers open.
inline std::filesystem::path model_path(const std::filesystem::path& output_dir) {
  return output_dir / "point_cloud.ply";
}

class ProgressLog;

class Trainer {
 public:
  Trainer(const TrainConfig& config, TrainerSetup setup, gs::GaussianModel initial);

  // Continues the run checkpointed in setup.output_dir exactly as if it had never stopped; no
  // starting model is built. Throws Error naming the checkpoint when it is missing or unreadable.
  static Trainer resumed(const TrainConfig& config, TrainerSetup setup);

  // Trains to config.iterations, printing progress; checkpoints every config.checkpoint_every
  // iterations and when SIGINT or SIGTERM arrives (then returns with summary.interrupted). Throws
  // Error when the loss or the parameters stop being finite; the last good checkpoint stays on
  // disk.
  TrainSummary run();

  // On the training device (core/device.hpp).
  const gs::GaussianModel& model() const { return model_; }
  const std::array<float, 3>& background() const { return setup_.background; }
  // "at iteration N of M", and whether the run had finished there: what a resume continues.
  std::string resume_point() const;
  std::filesystem::path checkpoint_path() const {
    return train::checkpoint_path(setup_.output_dir);
  }

  // Mean PSNR of the model on `views` (all of them).
  double evaluate_psnr(const std::vector<TrainView>& views) const;

 private:
  void load_checkpoint();
  void restore_extras(gs::CheckpointExtras& extras);  // the iteration, random states, ...
  // The training cameras as 3DGS saves them for viewers; also what --resume compares against.
  std::filesystem::path cameras_path() const { return setup_.output_dir / "cameras.json"; }
  void require_same_cameras() const;                           // as cameras_path() holds them
  void require_own_config(const torch::Tensor& stored) const;  // the config a checkpoint keeps
  torch::Tensor background_tensor() const;
  double step(int64_t iteration);  // one optimizer step; returns the loss
  std::vector<int> pick_views();
  // After a step, on 3DGS's and Mip-Splatting's schedules: densification and pruning, opacity
  // resets, and the 3D filter's updates.
  void refine(int64_t iteration);
  int64_t densify_cap() const;  // config.max_gaussians, or fewer when memory runs short
  void warn_memory_cap(int64_t iteration, int64_t cap, int64_t held_back);
  void save_checkpoint();
  [[noreturn]] void fail_diverged(int64_t iteration, double loss) const;
  // Out of memory (call it inside a catch block): the error says when, what is kept and what caps
  // the model's growth.
  [[noreturn]] void fail_out_of_memory() const;
  // run's loop: each step, its reports, densification and checkpoints. False when it stopped for
  // an interrupt, after its checkpoint.
  bool train_until_done_or_stopped(ProgressLog& log);
  // "the last good checkpoint (iteration N) is kept in PATH", or that there is none yet.
  std::string checkpoint_kept() const;
  double training_seconds() const;

  TrainConfig config_;
  torch::Device device_ = compute_device();  // holds the model, the targets and the optimizer
  TrainerSetup setup_;
  gs::GaussianModel model_;
  std::optional<gs::GaussianOptimizer> optimizer_;
  gs::DensifyStats stats_;
  std::vector<Camera> train_cameras_;
  std::mt19937_64 view_rng_;
  int64_t iteration_ = 0;              // completed iterations
  int64_t checkpoint_iteration_ = -1;  // of the last checkpoint written or read
  double seconds_before_ = 0;          // training time of the runs before a resume
  // The last step's loss and test report, checkpointed so that resuming a finished run reports
  // them rather than zeros.
  double last_loss_ = 0;
  std::optional<double> last_test_psnr_;
  bool memory_capped_ = false;  // densification was held back for memory (warned once)
  Stopwatch run_watch_;         // this process's training time
};

}  // namespace iesrgs::train
