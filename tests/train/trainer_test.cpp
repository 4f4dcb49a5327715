#include "train/trainer.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/device.hpp"
#include "gs/checkpoint.hpp"
#include "io/atomic_file.hpp"
#include "io/ply.hpp"
#include "loss/autograd.hpp"
#include "support/cuda_device.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"
#include "train/session.hpp"

namespace iesrgs::train {
namespace {

using testing::error_message;
using testing::TempDir;

// A small synthetic scene shared by the tests: 10 train and 2 test views of 40x40.
class TrainerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    synth::SynthOptions options;
    options.size = 40;
    options.train_views = 10;
    options.test_views = 2;
    options.seed = 5;
    synth::write_synth_dataset(dir_->path() / "scene", options);
    scene_ = new Scene(load_scene(dir_->path() / "scene"));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete dir_;
  }

  TrainerSetup setup(const std::filesystem::path& out) const {
    ViewImages images(*scene_);
    TrainerSetup s;
    s.train_views = load_views(*scene_, Split::Train, images);
    s.test_views = load_views(*scene_, Split::Test, images);
    s.background = scene_->background;
    s.scene_extent = scene_->normalization().radius;
    s.output_dir = out;
    return s;
  }

  static TrainConfig config() {
    TrainConfig c = make_preset("fast", 40);
    c.views_per_iteration = 3;
    c.densify_every = 10;
    c.checkpoint_every = 0;
    c.test_every = 0;
    c.random_points = 2000;
    c.init = "random";
    return c;
  }

  gs::GaussianModel initial() const { return initial_model(*scene_, config(), {}); }

  static TempDir* dir_;
  static Scene* scene_;
};

TempDir* TrainerTest::dir_ = nullptr;
Scene* TrainerTest::scene_ = nullptr;

std::vector<Camera> cameras(const TrainerSetup& s) {
  std::vector<Camera> result;
  for (const TrainView& view : s.train_views) result.push_back(view.camera);
  return result;
}

double max_difference(const gs::GaussianModel& a, const gs::GaussianModel& b) {
  double largest = 0;
  for (int p = 0; p < gs::kParamCount; ++p) {
    const torch::Tensor& x = a.param(gs::Param(p));
    const torch::Tensor& y = b.param(gs::Param(p));
    if (x.sizes() != y.sizes()) return std::numeric_limits<double>::infinity();
    largest = std::max(largest, (x - y).abs().max().item<double>());
  }
  return largest;
}

TEST_F(TrainerTest, FittingRaisesTestPsnrAndDensifies) {
  TempDir out;
  TrainerSetup s = setup(out.path());
  const std::vector<TrainView> test = s.test_views;
  Trainer trainer(config(), std::move(s), initial());
  const double before = trainer.evaluate_psnr(test);
  const int64_t start_size = trainer.model().size();
  const TrainSummary summary = trainer.run();
  EXPECT_EQ(summary.iterations, 40);
  EXPECT_FALSE(summary.test_psnr.has_value());  // test_every 0: no report, not a PSNR of 0
  EXPECT_GT(trainer.evaluate_psnr(test), before + 3) << "before " << before;
  EXPECT_NE(trainer.model().size(), start_size);
  EXPECT_TRUE(std::filesystem::exists(trainer.checkpoint_path()));  // the last iteration's
  EXPECT_TRUE(std::filesystem::exists(out / "train_log.csv"));
}

// Training on the GPU: the same schedule and losses, densification and 3D filter included, ends
// as close to the CPU run as two float orders of summation allow.
TEST_F(TrainerTest, CudaTrainingMatchesCpu) {
  IESRGS_SKIP_WITHOUT_CUDA();
  TempDir cpu_dir, gpu_dir;
  TrainConfig c = config();
  c.iterations = 300;
  Trainer cpu(c, setup(cpu_dir.path()), initial());
  cpu.run();
  set_compute_device(torch::kCUDA);
  Trainer gpu(c, setup(gpu_dir.path()), initial());
  const TrainSummary summary = gpu.run();
  set_compute_device(torch::kCPU);
  ASSERT_TRUE(gpu.model().means.is_cuda());
  const std::vector<TrainView> test = setup(cpu_dir.path()).test_views;
  EXPECT_EQ(summary.iterations, 300);
  EXPECT_NEAR(gpu.evaluate_psnr(test), cpu.evaluate_psnr(test), 0.3);
  EXPECT_NEAR(double(gpu.model().size()), double(cpu.model().size()), 0.1 * cpu.model().size());
}

// Multi-view regulation: each step renders K = 3 distinct views and its loss is the sum of theirs.
TEST_F(TrainerTest, EachStepSumsTheLossesOfThreeDistinctViews) {
  TempDir out;
  TrainerSetup s = setup(out.path());
  std::vector<int> views;
  s.loss = [&](int view, const raster::RenderOutput& render) {
    views.push_back(view);
    return render.image.sum() * 0 + double(view + 1);
  };
  Trainer trainer(config(), s, initial());
  const TrainSummary summary = trainer.run();
  ASSERT_EQ(views.size(), size_t(3 * summary.iterations));
  std::vector<int> seen(s.train_views.size(), 0);
  for (size_t i = 0; i < views.size(); i += 3) {
    EXPECT_NE(views[i], views[i + 1]);
    EXPECT_NE(views[i], views[i + 2]);
    EXPECT_NE(views[i + 1], views[i + 2]);
    for (size_t j = i; j < i + 3; ++j) ++seen[size_t(views[j])];
  }
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 0), 0);  // 120 draws reach all 10 views
  const size_t last = views.size() - 3;
  EXPECT_EQ(summary.final_loss, double(views[last] + views[last + 1] + views[last + 2] + 3));
}

// The schedule as the loss sees it, iteration by iteration: the SH degree steps up every
// sh_increase_every; the model changes size only after a densification step inside the window;
// opacities drop to a tenth only after a reset inside it (over black: no reset at densify_from).
TEST_F(TrainerTest, RefinesOnItsSchedule) {
  TempDir out;
  TrainerSetup s = setup(out.path());
  s.background = {0, 0, 0};
  TrainConfig c = config();
  c.views_per_iteration = 1;
  c.max_sh_degree = 2;
  c.sh_increase_every = 10;
  c.densify_from = 5;
  c.densify_until = 25;
  c.densify_every = 5;
  c.opacity_reset_every = 15;
  struct Seen {
    int sh_degree;
    int64_t size;
    double mean_opacity;
  };
  std::vector<Seen> seen;  // seen[i - 1]: at iteration i, after refining at i - 1
  const Trainer* trainer = nullptr;
  const std::vector<TrainView> views = s.train_views;
  s.loss = [&](int view, const raster::RenderOutput& render) {
    const gs::GaussianModel& model = trainer->model();
    seen.push_back({model.active_sh_degree, model.size(),
                    torch::sigmoid(model.opacity_logits).mean().item<double>()});
    return loss::photometric_autograd(render.image, views[size_t(view)].target, c.dssim_weight);
  };
  Trainer run(c, s, initial());
  trainer = &run;
  run.run();
  ASSERT_EQ(seen.size(), 40u);
  bool resized = false;
  for (int i = 1; i <= 40; ++i) {
    EXPECT_EQ(seen[i - 1].sh_degree, std::min(2, i / 10)) << "iteration " << i;
    if (i == 40) break;
    const Seen &now = seen[i - 1], &next = seen[i];
    const bool densified = i == 10 || i == 15 || i == 20;
    if (!densified) {
      EXPECT_EQ(next.size, now.size) << "after iteration " << i;
    }
    resized |= next.size != now.size;
    const bool reset = next.mean_opacity < 0.5 * now.mean_opacity;
    EXPECT_EQ(reset, i == 15) << "after iteration " << i << ": " << now.mean_opacity << " -> "
                              << next.mean_opacity;
  }
  EXPECT_TRUE(resized);
}

TEST_F(TrainerTest, MaxGaussiansCapsTheGrowth) {
  TempDir free_dir, capped_dir;
  Trainer free(config(), setup(free_dir.path()), initial());
  ASSERT_GT(free.run().gaussians, 2000);  // the cap below binds
  TrainConfig c = config();
  c.max_gaussians = 2000;
  Trainer capped(c, setup(capped_dir.path()), initial());
  EXPECT_LE(capped.run().gaussians, 2000);
}

TEST_F(TrainerTest, InterruptedRunResumesToTheSameModel) {
  TempDir straight_dir, resumed_dir;
  Trainer straight(config(), setup(straight_dir.path()), initial());
  straight.run();

  // SIGINT in the middle of iteration 17: the loop checkpoints after it and returns.
  TrainerSetup s = setup(resumed_dir.path());
  int calls = 0;
  const ViewLoss photometric = [&](int view, const raster::RenderOutput& render) {
    if (++calls == 17 * 3) {
      std::this_thread::sleep_for(std::chrono::seconds(1));  // a first run of at least 1 s
      std::raise(SIGINT);
    }
    const torch::Tensor& target = s.train_views[size_t(view)].target;
    return loss::photometric_autograd(render.image, target, 0.2);
  };
  TrainerSetup interrupted_setup = s;
  interrupted_setup.loss = photometric;
  Trainer first(config(), interrupted_setup, initial());
  const TrainSummary partial = first.run();
  ASSERT_TRUE(partial.interrupted);
  EXPECT_EQ(partial.iterations, 17);

  Trainer second = Trainer::resumed(config(), s);
  const auto start = std::chrono::steady_clock::now();
  const TrainSummary resumed = second.run();
  const std::chrono::duration<double> second_run = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(resumed.iterations, 40);
  EXPECT_EQ(max_difference(second.model(), straight.model()), 0.0);
  // Both runs' training time: the first run's (at least the 1 s it slept) and the second's own,
  // which its run() call holds.
  EXPECT_GT(resumed.seconds, partial.seconds);
  EXPECT_GT(resumed.seconds, second_run.count());
  EXPECT_LT(resumed.seconds, partial.seconds + second_run.count());
  // A log row every log_every (10) iterations and at the interruption, in order, across both
  // runs.
  std::istringstream log(read_file(resumed_dir / "train_log.csv"));
  std::string row;
  std::getline(log, row);
  std::vector<int> iterations;
  while (std::getline(log, row)) iterations.push_back(std::stoi(row));
  EXPECT_EQ(iterations, (std::vector<int>{10, 17, 20, 30, 40}));
}

// SIGTERM (kill, timeout, a container stopping) checkpoints and returns as Ctrl-C does.
TEST_F(TrainerTest, TerminationCheckpointsAsCtrlCDoes) {
  TempDir out;
  TrainerSetup s = setup(out.path());
  const std::vector<TrainView> views = s.train_views;
  int calls = 0;
  s.loss = [&](int view, const raster::RenderOutput& render) {
    if (++calls == 5 * 3) std::raise(SIGTERM);
    return loss::photometric_autograd(render.image, views[size_t(view)].target, 0.2);
  };
  Trainer trainer(config(), std::move(s), initial());
  const TrainSummary summary = trainer.run();
  EXPECT_TRUE(summary.interrupted);
  EXPECT_EQ(summary.iterations, 5);
  EXPECT_TRUE(std::filesystem::exists(trainer.checkpoint_path()));
}

TEST_F(TrainerTest, NonFiniteLossStopsWithTheCheckpointNamed) {
  TempDir out;
  TrainerSetup s = setup(out.path());
  int calls = 0;
  s.loss = [&](int, const raster::RenderOutput& render) {
    ++calls;
    const double poison = calls > 3 * 12 ? std::numeric_limits<double>::quiet_NaN() : 1.0;
    return render.image.mean() * poison;
  };
  TrainConfig c = config();
  c.checkpoint_every = 5;
  Trainer trainer(c, std::move(s), initial());
  const std::string message = error_message([&] { trainer.run(); });
  EXPECT_NE(message.find("diverged at iteration 13"), std::string::npos) << message;
  EXPECT_NE(message.find("iteration 10"), std::string::npos) << message;
  EXPECT_NE(message.find("checkpoint.pt"), std::string::npos) << message;
}

TEST_F(TrainerTest, NonFiniteParametersStopTrainingBeforeItEnds) {
  // A learning rate past float's range makes the opacities infinite while the loss stays finite:
  // 40 iterations never reach a periodic check, so the last one must catch it.
  TempDir out;
  TrainConfig c = config();
  c.learning_rates.opacity = 1e39;
  Trainer trainer(c, setup(out.path()), initial());
  const std::string message = error_message([&] { trainer.run(); });
  EXPECT_NE(message.find("training diverged at iteration"), std::string::npos) << message;
}

// A checkpoint due on a broken model stops the run there rather than skipping the write.
TEST_F(TrainerTest, NonFiniteParametersStopAtTheNextCheckpoint) {
  TempDir out;
  TrainConfig c = config();
  c.learning_rates.opacity = 1e39;
  c.checkpoint_every = 5;
  Trainer trainer(c, setup(out.path()), initial());
  const std::string message = error_message([&] { trainer.run(); });
  EXPECT_NE(message.find("diverged at iteration 5:"), std::string::npos) << message;
  EXPECT_NE(message.find("no checkpoint was written yet"), std::string::npos) << message;
}

TEST_F(TrainerTest, ResumeWithoutCheckpointIsAClearError) {
  TempDir out;
  EXPECT_NE(
      error_message([&] { Trainer::resumed(config(), setup(out.path())); }).find("no checkpoint"),
      std::string::npos);
}

// A checkpoint damaged or written by another program, yet a readable archive, is refused naming
// the file, before any of it is trained on.
TEST_F(TrainerTest, TamperedCheckpointsAreRefused) {
  TempDir out;
  TrainConfig c = config();
  c.iterations = 4;
  Trainer(c, setup(out.path()), initial()).run();
  const std::filesystem::path file = out / "checkpoint.pt";
  const std::string original = read_file(file);
  // The error of resuming after `tamper` changed the stored state.
  const auto resume_error = [&](const std::function<void(gs::GaussianModel&, gs::GaussianOptimizer&,
                                                         gs::CheckpointExtras&)>& tamper) {
    gs::GaussianModel model;
    gs::GaussianOptimizer optimizer(initial(), {}, 1);
    gs::DensifyStats stats;
    gs::CheckpointExtras extras{
        {"iteration", {}}, {"view_rng", {}}, {"torch_rng", {}}, {"background", {}}};
    gs::load_training_state(file, model, optimizer, stats, &extras);
    tamper(model, optimizer, extras);
    gs::save_training_state(file, model, optimizer, stats, extras);
    const std::string message = error_message([&] { Trainer::resumed(c, setup(out.path())); });
    write_file_atomically(file, original);
    EXPECT_TRUE(testing::contains(message, file.string() + ": ")) << message;
    return message;
  };
  using Extras = gs::CheckpointExtras;
  EXPECT_TRUE(testing::contains(
      resume_error([](auto&, auto&, Extras& e) { e["iteration"] = torch::tensor(int64_t(5)); }),
      "stored at iteration 5, outside the 0..4 iterations"));
  EXPECT_TRUE(testing::contains(resume_error([](auto&, auto&, Extras& e) {
                                  e["iteration"] = torch::tensor({1, 2});
                                }),
                                "iteration holds 2 values, not one"));
  EXPECT_TRUE(testing::contains(
      resume_error([](auto&, auto&, Extras& e) { e["background"] = torch::tensor({0.5f}); }),
      "trained over the background 0.5, not 1,1,1"));
  EXPECT_TRUE(testing::contains(resume_error([](auto&, auto&, Extras& e) {
                                  e["torch_rng"] = torch::zeros({3}, torch::kUInt8);
                                }),
                                "not a readable training checkpoint ("));
  EXPECT_TRUE(testing::contains(
      resume_error([](gs::GaussianModel& m, auto&, Extras&) { m.means.data()[0][0] = NAN; }),
      "holds non-finite parameters"));
  EXPECT_TRUE(testing::contains(resume_error([](auto&, gs::GaussianOptimizer& o, Extras&) {
                                  torch::Tensor first = o.moments(gs::Param::Means).first;
                                  first.view(-1)[0] = NAN;  // shares the optimizer's storage
                                }),
                                "non-finite parameters or optimizer moments"));
  write_file_atomically(out / "cameras.json", "[{\"id\": 0,");
  EXPECT_TRUE(testing::contains(error_message([&] { Trainer::resumed(c, setup(out.path())); }),
                                "cameras.json: damaged (not valid JSON)"));
  std::filesystem::remove(out / "cameras.json");
  EXPECT_TRUE(testing::contains(error_message([&] { Trainer::resumed(c, setup(out.path())); }),
                                "cameras.json: missing beside the checkpoint"));
}

// A checkpoint copied from a run of another config (another seed, say) is not this run's.
TEST_F(TrainerTest, ACheckpointOfAnotherConfigIsRefused) {
  TempDir out;
  TrainConfig c = config();
  c.iterations = 4;
  Trainer(c, setup(out.path()), initial()).run();
  TrainConfig other = c;
  other.seed = c.seed + 1;
  EXPECT_TRUE(testing::contains(
      error_message([&] { Trainer::resumed(other, setup(out.path())); }),
      "checkpoint.pt: written by a run of another config: this run has seed " +
          std::to_string(other.seed) + " instead of " + std::to_string(c.seed) + "; resume"));
  EXPECT_EQ(Trainer::resumed(c, setup(out.path())).resume_point(),
            "at iteration 4 of 4 (finished: writing its outputs again)");
}

// Checkpoints of older versions hold only the required extras; they resume as before.
TEST_F(TrainerTest, CheckpointWithoutTheOptionalExtrasResumes) {
  TempDir out;
  TrainConfig c = config();
  c.iterations = 6;
  c.checkpoint_every = 3;
  TrainerSetup s = setup(out.path());
  const std::vector<TrainView> views = s.train_views;
  int calls = 0;
  s.loss = [&](int view, const raster::RenderOutput& render) {
    if (++calls == 3 * 3) std::raise(SIGINT);  // checkpoints after iteration 3
    return loss::photometric_autograd(render.image, views[size_t(view)].target, 0.2);
  };
  ASSERT_TRUE(Trainer(c, s, initial()).run().interrupted);
  const std::filesystem::path file = out / "checkpoint.pt";
  gs::GaussianModel model;
  gs::GaussianOptimizer optimizer(initial(), {}, 1);
  gs::DensifyStats stats;
  gs::CheckpointExtras extras{{"iteration", {}}, {"view_rng", {}}, {"torch_rng", {}}};
  gs::load_training_state(file, model, optimizer, stats, &extras);
  gs::save_training_state(file, model, optimizer, stats, extras);  // without seconds, loss, ...
  const TrainSummary resumed = Trainer::resumed(c, setup(out.path())).run();
  EXPECT_FALSE(resumed.interrupted);
  EXPECT_EQ(resumed.iterations, 6);
}

TEST_F(TrainerTest, EmptyStartingPlyIsAClearError) {
  TempDir dir;
  write_ply(dir / "empty.ply", SplatCloud{});
  const std::string message =
      error_message([&] { initial_model(*scene_, config(), dir / "empty.ply"); });
  EXPECT_NE(message.find("empty.ply: has no Gaussians to start training from"), std::string::npos)
      << message;
}

// Pruning every Gaussian would end in an empty point cloud, which no command reads.
TEST_F(TrainerTest, PruningEveryGaussianStopsTraining) {
  TempDir dir;
  TrainConfig c = config();
  c.min_opacity = 0.999;  // above every starting opacity
  Trainer trainer(c, setup(dir.path()), initial());
  const std::string message = error_message([&] { trainer.run(); });
  EXPECT_NE(message.find("densification pruned every Gaussian (min_opacity 0.999"),
            std::string::npos)
      << message;
}

TEST_F(TrainerTest, PointCloudsRoundTripThroughPly) {
  TempDir out;
  TrainerSetup gray = setup(out.path());
  gray.background = {0.25f, 0.5f, 0.75f};
  Trainer trainer(config(), std::move(gray), initial());
  trainer.run();
  write_point_clouds(out.path(), trainer);
  const SplatCloud cloud = read_ply(out / "point_cloud.ply");
  const gs::GaussianModel back = gs::model_from_splat_cloud(cloud);
  EXPECT_LT(max_difference(back, trainer.model()), 1e-6);
  EXPECT_TRUE(back.antialiased);
  EXPECT_EQ(cloud.background, trainer.background());  // what render then draws behind it
  EXPECT_EQ(read_ply(out / "point_cloud_filter_baked.ply").background, trainer.background());
}

// A 3DGS model as the start (drawn with the dilation) still trains as Mip-Splatting.
TEST_F(TrainerTest, TrainingIsAntialiasedWhateverTheStart) {
  TempDir out;
  gs::GaussianModel classic = initial();
  classic.antialiased = false;
  const Trainer trainer(config(), setup(out.path()), classic);
  EXPECT_TRUE(trainer.model().antialiased);
}

// A start model's 3D filter belongs to other cameras (an LR model cloned for HR training).
TEST_F(TrainerTest, StartModelsFilterIsRecomputedForTheseCameras) {
  TempDir out;
  gs::GaussianModel start = initial();
  gs::update_filter_3d(start, cameras(setup(out.path())));
  const torch::Tensor expected = start.filter_3d.clone();
  start.filter_3d = expected * 4;
  const Trainer trainer(config(), setup(out.path()), start);
  EXPECT_TRUE(torch::allclose(trainer.model().filter_3d, expected));
}

}  // namespace
}  // namespace iesrgs::train
