#include "gs/optimizer.hpp"

#include <gtest/gtest.h>
#include <torch/optim/adam.h>

#include <cmath>

#include "gs/checkpoint.hpp"
#include "gs/densify.hpp"
#include "gs/random_model.hpp"
#include "io/atomic_file.hpp"
#include "raster/autograd.hpp"
#include "raster/raster_test_scene.hpp"
#include "raster/rasterizer.hpp"
#include "support/cuda_device.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::gs {
namespace {

void set_random_grads(GaussianModel& m) {
  for (int p = 0; p < kParamCount; ++p)
    m.param(Param(p)).mutable_grad() = torch::randn_like(m.param(Param(p))) * 0.1;
}

TEST(GaussianOptimizer, ExponentialScheduleFollows3dgsFormula) {
  // 3DGS: exp(log(a) (1 - t) + log(b) t), t = step / max_steps clamped to [0, 1].
  const ExponentialLr lr{3.2e-4, 3.2e-6, 30000};
  EXPECT_NEAR(lr(0), 3.2e-4, 1e-15);
  EXPECT_NEAR(lr(7500), 3.2e-4 * std::pow(0.01, 0.25), 1e-15);  // a^0.75 b^0.25
  EXPECT_NEAR(lr(15000), 3.2e-5, 1e-15);                        // geometric mean
  EXPECT_NEAR(lr(30000), 3.2e-6, 1e-15);
  EXPECT_NEAR(lr(45000), 3.2e-6, 1e-15);
  EXPECT_EQ(lr(-1), 0);
}

TEST(GaussianOptimizer, GroupRatesAre3dgsDefaultsWithPositionTimesExtent) {
  const GaussianModel m = random_model(2);
  const GaussianOptimizer opt(m, LearningRates{}, 4.0);
  // The first step is 3DGS's iteration 1.
  EXPECT_NEAR(opt.learning_rate(Param::Means), 6.4e-4 * std::pow(0.01, 1.0 / 30000), 1e-15);
  EXPECT_EQ(opt.learning_rate(Param::ShDc), 2.5e-3);
  EXPECT_EQ(opt.learning_rate(Param::ShRest), 2.5e-3 / 20);
  EXPECT_EQ(opt.learning_rate(Param::OpacityLogits), 0.05);
  EXPECT_EQ(opt.learning_rate(Param::LogScales), 5e-3);
  EXPECT_EQ(opt.learning_rate(Param::Quats), 1e-3);
}

TEST(GaussianOptimizer, FusedStepMatchesTorchAdam) {
  torch::manual_seed(1);
  GaussianModel fused = random_model(300);
  std::vector<torch::Tensor> reference;
  for (int p = 0; p < kParamCount; ++p)
    reference.push_back(fused.param(Param(p)).detach().clone().requires_grad_(true));
  LearningRates rates;
  rates.position_max_steps = 4;  // a decaying position rate within the test
  GaussianOptimizer opt(fused, rates, 2.5);
  std::vector<torch::optim::OptimizerParamGroup> groups;
  for (int p = 0; p < kParamCount; ++p)
    groups.emplace_back(std::vector<torch::Tensor>{reference[p]},
                        std::make_unique<torch::optim::AdamOptions>(
                            torch::optim::AdamOptions(opt.learning_rate(Param(p))).eps(1e-15)));
  torch::optim::Adam adam(groups);
  for (int step = 0; step < 6; ++step) {
    set_random_grads(fused);
    for (int p = 0; p < kParamCount; ++p) {
      reference[p].mutable_grad() = fused.param(Param(p)).grad().clone();
      static_cast<torch::optim::AdamOptions&>(adam.param_groups()[p].options())
          .lr(opt.learning_rate(Param(p)));
    }
    opt.step(fused);
    adam.step();
    for (int p = 0; p < kParamCount; ++p)
      ASSERT_LE((fused.param(Param(p)) - reference[p]).abs().max().item<float>(), 1e-6)
          << "group " << p << " step " << step;
  }
  EXPECT_EQ(opt.steps_taken(), 6);
  EXPECT_NEAR(opt.learning_rate(Param::Means), 1.6e-6 * 2.5, 1e-18);
}

TEST(GaussianOptimizer, CudaStepMatchesCpu) {
  IESRGS_SKIP_WITHOUT_CUDA();
  torch::manual_seed(4);
  GaussianModel cpu = random_model(500);
  GaussianModel gpu = cpu.to(torch::kCUDA);
  GaussianOptimizer cpu_opt(cpu, {}, 1.5), gpu_opt(gpu, {}, 1.5);
  for (int step = 0; step < 3; ++step) {
    set_random_grads(cpu);
    for (int p = 0; p < kParamCount; ++p)
      gpu.param(Param(p)).mutable_grad() = cpu.param(Param(p)).grad().to(torch::kCUDA);
    cpu_opt.step(cpu);
    gpu_opt.step(gpu);
  }
  for (int p = 0; p < kParamCount; ++p) {
    ASSERT_TRUE(gpu.param(Param(p)).is_cuda());
    EXPECT_LE((gpu.param(Param(p)).cpu() - cpu.param(Param(p))).abs().max().item<float>(), 1e-6)
        << "group " << p;
  }
}

TEST(GaussianOptimizer, StepNeedsEveryGradient) {
  GaussianModel m = random_model(2);
  GaussianOptimizer opt(m, {}, 1);
  EXPECT_NE(testing::error_message([&] { opt.step(m); }).find("means has no gradient"),
            std::string::npos);
}

TEST(GaussianOptimizer, MomentRowsGrowShrinkAndReset) {
  GaussianModel m = random_model(4);
  GaussianOptimizer opt(m, {}, 1);
  set_random_grads(m);
  opt.step(m);
  const torch::Tensor first = opt.moments(Param::ShRest).first.clone();
  opt.append_rows(2);
  ASSERT_EQ(opt.moments(Param::ShRest).first.sizes(), (c10::IntArrayRef{6, 15, 3}));
  EXPECT_TRUE(torch::equal(opt.moments(Param::ShRest).first.narrow(0, 0, 4), first));
  EXPECT_EQ(opt.moments(Param::ShRest).second.narrow(0, 4, 2).abs().sum().item<float>(), 0.f);
  opt.keep_rows(torch::tensor({true, false, true, false, false, true}));
  EXPECT_TRUE(torch::equal(opt.moments(Param::ShRest).first[1], first[2]));
  EXPECT_EQ(opt.moments(Param::Means).second.size(0), 3);
  opt.reset_moments(Param::OpacityLogits);
  EXPECT_EQ(opt.moments(Param::OpacityLogits).first.abs().sum().item<float>(), 0.f);
  EXPECT_EQ(opt.moments(Param::OpacityLogits).second.abs().sum().item<float>(), 0.f);
  EXPECT_GT(opt.moments(Param::Quats).second.abs().sum().item<float>(), 0.f);
}

TEST(GaussianOptimizer, CheckpointResumesBitExactly) {
  testing::TempDir dir;
  torch::manual_seed(2);
  GaussianModel m = random_model(20);
  m.filter_3d = torch::rand({20});
  m.active_sh_degree = 1;
  GaussianOptimizer opt(m, {}, 3);
  DensifyStats stats = DensifyStats::zeros(20);
  stats.grad_sum = torch::rand({20});
  for (int i = 0; i < 3; ++i) {
    set_random_grads(m);
    opt.step(m);
  }
  save_training_state(dir / "state.pt", m, opt, stats);

  GaussianModel resumed = random_model(5);
  GaussianOptimizer resumed_opt(resumed, {}, 3);
  DensifyStats resumed_stats = DensifyStats::zeros(5);
  load_training_state(dir / "state.pt", resumed, resumed_opt, resumed_stats);
  EXPECT_EQ(resumed_opt.steps_taken(), 3);
  EXPECT_EQ(resumed.active_sh_degree, 1);
  EXPECT_TRUE(torch::equal(resumed.filter_3d, m.filter_3d));
  EXPECT_TRUE(torch::equal(resumed_stats.grad_sum, stats.grad_sum));
  set_random_grads(m);
  for (int p = 0; p < kParamCount; ++p)
    resumed.param(Param(p)).mutable_grad() = m.param(Param(p)).grad().clone();
  opt.step(m);
  resumed_opt.step(resumed);
  for (int p = 0; p < kParamCount; ++p) {
    EXPECT_TRUE(resumed.param(Param(p)).requires_grad());
    EXPECT_TRUE(torch::equal(resumed.param(Param(p)), m.param(Param(p)))) << p;
    EXPECT_TRUE(torch::equal(resumed_opt.moments(Param(p)).second, opt.moments(Param(p)).second));
  }
}

TEST(GaussianOptimizer, CorruptCheckpointNamesTheFile) {
  testing::TempDir dir;
  testing::write_text(dir / "bad.pt", "not a checkpoint");
  GaussianModel m = random_model(2);
  GaussianOptimizer opt(m, {}, 1);
  DensifyStats stats = DensifyStats::zeros(2);
  const std::string message =
      testing::error_message([&] { load_training_state(dir / "bad.pt", m, opt, stats); });
  EXPECT_NE(message.find("bad.pt: not a readable training checkpoint"), std::string::npos);
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_EQ(m.size(), 2);
}

// LibTorch's reader does not check the CRCs: a damaged tensor must not load as a model.
TEST(GaussianOptimizer, DamagedCheckpointIsRefused) {
  testing::TempDir dir;
  GaussianModel m = random_model(4);
  m.means.data().fill_(1234.5f);
  GaussianOptimizer opt(m, {}, 1);
  save_training_state(dir / "state.pt", m, opt, DensifyStats::zeros(4));
  std::string bytes = read_file(dir / "state.pt");
  const float marker = 1234.5f;
  const size_t at = bytes.find(std::string(reinterpret_cast<const char*>(&marker), 4));
  ASSERT_NE(at, std::string::npos);
  bytes[at] ^= 1;
  testing::write_text(dir / "state.pt", bytes);

  GaussianModel loaded = random_model(2);
  GaussianOptimizer loaded_opt(loaded, {}, 1);
  DensifyStats stats = DensifyStats::zeros(2);
  const std::string message = testing::error_message(
      [&] { load_training_state(dir / "state.pt", loaded, loaded_opt, stats); });
  EXPECT_NE(message.find("state.pt: not a readable training checkpoint"), std::string::npos);
  EXPECT_NE(message.find("fails its CRC"), std::string::npos) << message;
  EXPECT_EQ(loaded.size(), 2);
}

// The pieces fit: one Adam step through the real rasterizer lowers an L1 loss.
TEST(GaussianOptimizer, OneStepThroughTheRasterizerLowersL1) {
  GaussianModel m = model_from_points({0, 0, 4, 0.3f, 0.2f, 4, -0.3f, -0.1f, 5},
                                      {0.2f, 0.2f, 0.2f, 0.1f, 0.3f, 0.2f, 0.2f, 0.2f, 0.1f});
  const Camera view = raster::testkit::test_camera(32, 24);
  update_filter_3d(m, {view});
  const raster::ViewspaceProbes probes{torch::zeros({3, 2}, torch::requires_grad()),
                                       torch::zeros({3, 2}, torch::requires_grad())};
  const auto l1 = [&] {
    const auto out = raster::render(raster::render_tensors(m), raster::raster_camera<float>(view),
                                    {0, 0, 0}, probes);
    return (out.image - torch::full({3, 24, 32}, 0.8f)).abs().mean();
  };
  GaussianOptimizer opt(m, {}, 1);
  const torch::Tensor before = l1();
  before.backward();
  opt.step(m);
  EXPECT_LT(l1().item<float>(), before.item<float>() - 1e-4f);
}

}  // namespace
}  // namespace iesrgs::gs
