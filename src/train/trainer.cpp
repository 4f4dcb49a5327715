#include "train/trainer.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <torch/torch.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "core/device.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/memory.hpp"
#include "core/torch_error.hpp"
#include "eval/metrics.hpp"
#include "gs/checkpoint.hpp"
#include "gs/densify.hpp"
#include "io/atomic_file.hpp"
#include "io/cameras_json.hpp"
#include "loss/autograd.hpp"
#include "raster/rasterizer.hpp"
#include "train/progress.hpp"

namespace iesrgs::train {

namespace {

torch::Tensor bytes_tensor(const std::string& bytes) {
  return torch::from_blob(const_cast<char*>(bytes.data()), {int64_t(bytes.size())}, torch::kUInt8)
      .clone();
}

std::string tensor_bytes(const torch::Tensor& tensor) {
  const torch::Tensor bytes = tensor.to(torch::kUInt8).contiguous();
  return std::string(reinterpret_cast<const char*>(bytes.data_ptr<uint8_t>()), bytes.numel());
}

double psnr(const torch::Tensor& image, const torch::Tensor& target) {
  const torch::Tensor reference = target.to(image.device());  // views given from the CPU
  const double mse = (image.clamp(0, 1) - reference).square().mean().item<double>();
  return eval::psnr_from_mse(std::max(mse, 1e-20));
}

bool finite(const torch::Tensor& values) {
  return !values.defined() || torch::isfinite(values).all().item<bool>();
}

bool model_is_finite(const gs::GaussianModel& model) {
  for (int p = 0; p < gs::kParamCount; ++p)
    if (!finite(model.param(gs::Param(p)))) return false;
  return true;
}

// Everything a checkpoint restores that the next step computes with.
bool restored_state_finite(const gs::GaussianModel& model, const gs::GaussianOptimizer& optimizer) {
  if (!model_is_finite(model) || !finite(model.filter_3d)) return false;
  for (int p = 0; p < gs::kParamCount; ++p) {
    const gs::AdamMoments& moments = optimizer.moments(gs::Param(p));
    if (!finite(moments.first) || !finite(moments.second)) return false;
  }
  return true;
}

// Parameters, gradients, Adam moments, densification statistics and the per-view projection
// buffers: the peak resident memory grows by about 1.5 KB per Gaussian (measured from 0.1M to 1M
// random points, docs/DATASETS.md).
constexpr int64_t kBytesPerGaussian = 1500;

// The trainer's own model on `device`: copied only when it is elsewhere.
void place_on(gs::GaussianModel& model, torch::Device device) {
  if (model.means.device() != device) model = model.to(device);
}

gs::DensifyOptions densify_options(const TrainConfig& c, int64_t iteration) {
  gs::DensifyOptions options;
  options.grad_threshold = c.grad_threshold;
  options.source =
      c.absolute_gradients ? gs::GradientSource::Absolute : gs::GradientSource::Viewspace;
  options.percent_dense = c.percent_dense;
  options.min_opacity = c.min_opacity;
  const bool after_reset = iteration > c.opacity_reset_every;
  options.max_screen_size = after_reset ? c.max_screen_size : 0;
  options.max_world_size = after_reset ? c.max_world_size : 0;
  return options;
}

}  // namespace

void require_training_memory(int64_t gaussians, torch::Device device) {
  require_memory(gaussians * kBytesPerGaussian, fmt::format("training {} Gaussians", gaussians),
                 device);
}

Trainer::Trainer(const TrainConfig& config, TrainerSetup setup, gs::GaussianModel initial)
    : config_(config), setup_(std::move(setup)), model_(std::move(initial)) {
  validate(config_);
  require_training_memory(model_.size(), device_);
  if (setup_.train_views.empty()) fail("training needs at least one view");
  for (const TrainView& view : setup_.train_views) train_cameras_.push_back(view.camera);
  torch::manual_seed(config_.seed);
  view_rng_.seed(config_.seed);
  model_.active_sh_degree = std::min(model_.active_sh_degree, config_.max_sh_degree);
  place_on(model_, device_);
  for (std::vector<TrainView>* views : {&setup_.train_views, &setup_.test_views})
    for (TrainView& view : *views) view.target = view.target.to(device_);
  gs::update_filter_3d(model_, train_cameras_);  // a start model's filter fits other cameras
  model_.antialiased = true;  // Mip-Splatting, whatever a starting .ply was drawn with
  optimizer_.emplace(model_, config_.learning_rates, setup_.scene_extent);
  stats_ = gs::DensifyStats::zeros(model_.size(), device_);
}

void Trainer::save_checkpoint() {
  // Never replace a good checkpoint with a broken model.
  if (!model_is_finite(model_)) fail_diverged(iteration_, last_loss_);
  std::ostringstream view_rng;
  view_rng << view_rng_;
  torch::Tensor torch_rng;
  {
    auto generator = at::detail::getDefaultCPUGenerator();
    std::lock_guard<std::mutex> lock(generator.mutex());
    torch_rng = generator.get_state();
  }
  gs::save_training_state(
      checkpoint_path(), model_, *optimizer_, stats_,
      {{"iteration", torch::tensor(iteration_)},
       {"view_rng", bytes_tensor(view_rng.str())},
       {"torch_rng", torch_rng},
       {"seconds", torch::tensor(training_seconds(), torch::kFloat64)},
       {"loss", torch::tensor(last_loss_, torch::kFloat64)},
       {"test_psnr", torch::tensor(last_test_psnr_.value_or(0), torch::kFloat64)},
       {"background", background_tensor()},
       {"config", bytes_tensor(to_json(config_).dump())}});
  checkpoint_iteration_ = iteration_;
}

torch::Tensor Trainer::background_tensor() const {
  return torch::tensor(std::vector<float>(setup_.background.begin(), setup_.background.end()));
}

Trainer Trainer::resumed(const TrainConfig& config, TrainerSetup setup) {
  // An empty model stands in until the checkpoint replaces the model, the optimizer and the
  // densification statistics together.
  Trainer trainer(config, std::move(setup), gs::model_from_points({}, {}));
  trainer.load_checkpoint();
  return trainer;
}

void Trainer::load_checkpoint() {
  const std::filesystem::path path = checkpoint_path();
  if (!std::filesystem::exists(path))
    fail_file(path, "no checkpoint to resume from (train without --resume first)");
  require_same_cameras();  // before reading a checkpoint that may not fit these views
  gs::CheckpointExtras extras{{"iteration", {}},  {"view_rng", {}}, {"torch_rng", {}},
                              {"seconds", {}},    {"loss", {}},     {"test_psnr", {}},
                              {"background", {}}, {"config", {}}};
  gs::load_training_state(path, model_, *optimizer_, stats_, &extras);  // onto the CPU
  // A model that diverged is never saved, so these were damaged or written by another program;
  // training from them would only diverge again, blaming the images.
  if (!restored_state_finite(model_, *optimizer_))
    fail_file(path, "holds non-finite parameters or optimizer moments (not saved by training)");
  place_on(model_, device_);
  optimizer_->to(device_);
  stats_.to(device_);
  try {
    restore_extras(extras);
  } catch (const c10::Error& e) {
    fail_file(path, "not a readable training checkpoint (" + torch_error_line(e) + ")");
  }
  checkpoint_iteration_ = iteration_;
}

void Trainer::restore_extras(gs::CheckpointExtras& extras) {
  const std::filesystem::path path = checkpoint_path();
  for (const char* required : {"iteration", "view_rng", "torch_rng"})
    if (!extras[required].defined())
      fail_file(path, fmt::format("not a training checkpoint of iesrgs train (no {})", required));
  // Checkpoints of older versions lack all but the required ones.
  const auto stored = [&](const char* name) {
    const torch::Tensor& value = extras[name];
    if (value.defined() && value.numel() != 1)
      fail_file(path, fmt::format("not a training checkpoint of iesrgs train ({} holds {} values, "
                                  "not one)",
                                  name, value.numel()));
    return value.defined() ? value.item<double>() : 0.0;
  };
  // The training images are composited over it: another one would change what the run learns.
  const torch::Tensor background = extras["background"].defined()
                                       ? extras["background"].to(torch::kFloat).flatten()
                                       : background_tensor();
  if (!background.equal(background_tensor()))
    fail_file(path, fmt::format("the run trained over the background {}, not {}: resume with the "
                                "same --background",
                                fmt::join(background.data_ptr<float>(),
                                          background.data_ptr<float>() + background.numel(), ","),
                                fmt::join(setup_.background, ",")));
  require_own_config(extras["config"]);
  const double iteration = stored("iteration");
  if (!(iteration >= 0 && iteration <= double(config_.iterations)))
    fail_file(path, fmt::format("stored at iteration {}, outside the 0..{} iterations of the run's "
                                "config.json",
                                iteration, config_.iterations));
  iteration_ = int64_t(iteration);
  seconds_before_ = stored("seconds");
  last_loss_ = stored("loss");
  // 0 stands for no report: a real one of 0 dB would need an error of 1 on every pixel.
  if (const double psnr = stored("test_psnr"); psnr > 0) last_test_psnr_ = psnr;
  std::istringstream view_rng(tensor_bytes(extras["view_rng"]));
  view_rng >> view_rng_;
  if (!view_rng) fail_file(path, "the stored view sampler state is corrupt");
  auto generator = at::detail::getDefaultCPUGenerator();
  std::lock_guard<std::mutex> lock(generator.mutex());
  generator.set_state(extras["torch_rng"]);
}

std::string Trainer::resume_point() const {
  return fmt::format(
      "at iteration {} of {}{}", iteration_, config_.iterations,
      iteration_ == config_.iterations ? " (finished: writing its outputs again)" : "");
}

void Trainer::require_own_config(const torch::Tensor& stored) const {
  if (!stored.defined()) return;  // written before checkpoints kept their config
  const std::filesystem::path path = checkpoint_path();
  const nlohmann::json json = nlohmann::json::parse(tensor_bytes(stored), nullptr, false);
  TrainConfig saved;
  try {
    apply_json(saved, json, "its config");
  } catch (const Error& e) {
    fail_file(path, fmt::format("not a readable training checkpoint ({})", e.what()));
  }
  // Copied from another run, say: its model would go on under this run's name and config.
  const std::vector<std::string> changes = config_changes(saved, config_);
  if (!changes.empty())
    fail_file(path, fmt::format("written by a run of another config: this run has {}; resume "
                                "in the folder it comes from, or train without --resume",
                                fmt::join(changes, ", ")));
}

void Trainer::require_same_cameras() const {
  // Resuming on other views (another --downscale, another scene) would go on training the model
  // on images it did not start from.
  const std::filesystem::path saved = cameras_path();
  // Training writes it before its first checkpoint: a checkpoint without it came from elsewhere.
  if (!std::filesystem::exists(saved))
    fail_file(saved,
              "missing beside the checkpoint, so the views it trained on are unknown (start "
              "the training over)");
  const std::string stored = read_file(saved);
  if (!nlohmann::json::accept(stored))
    fail_file(saved,
              "damaged (not valid JSON), so the views it trained on are unknown (start the "
              "training over)");
  if (stored != cameras_json(train_cameras_))
    fail_file(saved,
              "the run trained on other cameras than the scene given now: resume with the same "
              "scene, --downscale and --test-every (a version of iesrgs that undistorts the "
              "scene's lens otherwise changes its cameras too: start the training over then)");
}

// K distinct views drawn afresh each step: multi-view regulation. The code of 3DGS and MVGS pops
// views from a shuffled stack refilled each epoch instead, which also evens out how often each
// view is seen.
std::vector<int> Trainer::pick_views() {
  std::vector<int> order(setup_.train_views.size());
  std::iota(order.begin(), order.end(), 0);
  const size_t count = setup_.views_per_step(config_);
  for (size_t i = 0; i < count; ++i) {  // partial Fisher-Yates: `count` distinct views
    std::uniform_int_distribution<size_t> pick(i, order.size() - 1);
    std::swap(order[i], order[pick(view_rng_)]);
  }
  order.resize(count);
  return order;
}

double Trainer::step(int64_t iteration) {
  if (iteration % config_.sh_increase_every == 0 && model_.active_sh_degree < config_.max_sh_degree)
    ++model_.active_sh_degree;
  std::vector<gs::ViewStatistics> view_stats;
  // Summed where the losses are and read once per step: on a GPU each read waits for the device.
  torch::Tensor sum =
      torch::zeros({}, torch::TensorOptions().dtype(torch::kFloat64).device(device_));
  for (int v : pick_views()) {
    const TrainView& view = setup_.train_views[size_t(v)];
    const auto probe_options = torch::TensorOptions().device(device_).requires_grad(true);
    raster::ViewspaceProbes probes{torch::zeros({model_.size(), 2}, probe_options),
                                   torch::zeros({model_.size(), 2}, probe_options)};
    const raster::RenderOutput render =
        raster::render(raster::render_tensors(model_), raster::raster_camera<float>(view.camera),
                       setup_.background, probes);
    const torch::Tensor loss =
        setup_.loss ? setup_.loss(v, render)
                    : loss::photometric_autograd(render.image, view.target, config_.dssim_weight);
    // Backward per view: the gradient of the sum without holding K render graphs at once.
    loss.backward();
    sum += loss.detach().to(torch::kFloat64);
    view_stats.push_back({probes.grad.grad(), probes.abs_grad.grad(), render.radii});
  }
  const double total = sum.item<double>();
  if (!std::isfinite(total)) fail_diverged(iteration, total);
  if (iteration < config_.densify_until) stats_.accumulate(view_stats);
  optimizer_->step(model_);
  for (int p = 0; p < gs::kParamCount; ++p)
    model_.param(gs::Param(p)).mutable_grad() = torch::Tensor();
  return total;
}

void Trainer::refine(int64_t iteration) {
  const TrainConfig& c = config_;
  if (iteration < c.densify_until) {
    if (iteration > c.densify_from && iteration % c.densify_every == 0) {
      gs::DensifyOptions options = densify_options(c, iteration);
      options.max_gaussians = densify_cap();
      const gs::DensifyCounts counts =
          gs::densify_and_prune(model_, *optimizer_, stats_, options, setup_.scene_extent);
      spdlog::debug("iteration {}: densification cloned {}, split {}, pruned {}: {} Gaussians",
                    iteration, counts.cloned, counts.split, counts.pruned, model_.size());
      if (counts.held_back > 0) warn_memory_cap(iteration, options.max_gaussians, counts.held_back);
      // An empty model would train on to an empty point cloud, which no command reads.
      if (model_.size() == 0)
        fail(
            "iteration {}: densification pruned every Gaussian (min_opacity {}, max_world_size "
            "{}, max_screen_size {}): nothing is left to train",
            iteration, c.min_opacity, c.max_world_size, c.max_screen_size);
      gs::update_filter_3d(model_, train_cameras_);
    }
    const bool white = setup_.background == std::array<float, 3>{1, 1, 1};
    if (iteration % c.opacity_reset_every == 0 || (white && iteration == c.densify_from)) {
      gs::reset_opacity(model_, *optimizer_);
      spdlog::debug("iteration {}: opacities reset", iteration);
    }
  } else if (iteration > c.densify_until && iteration % c.filter_update_every == 0 &&
             iteration < c.iterations - 100) {
    // As Mip-Splatting: keep the filter current after densification, but not in the last steps.
    gs::update_filter_3d(model_, train_cameras_);
  }
}

void Trainer::warn_memory_cap(int64_t iteration, int64_t cap, int64_t held_back) {
  // The config's cap is the user's choice; the memory's is worth saying, once.
  if (memory_capped_ || (config_.max_gaussians > 0 && cap >= config_.max_gaussians)) return;
  memory_capped_ = true;
  spdlog::warn(
      "iteration {}: densification held to {} Gaussians, as many as the available memory holds "
      "({} more were due to clone or split); from here it grows only as memory allows",
      iteration, cap, held_back);
}

int64_t Trainer::densify_cap() const {
  // Linux overcommits: growing past the available memory would get the process killed later, and
  // on a GPU stop the run with an out-of-memory error.
  const int64_t available = available_memory_bytes(device_);
  const int64_t configured =
      config_.max_gaussians > 0 ? config_.max_gaussians : std::numeric_limits<int64_t>::max();
  if (available < 0) return configured;
  // A training step's buffers are freed between steps: what this training has held above its
  // present size (on the CPU, where that is measured) is taken again by the next step.
  const int64_t step_buffers =
      device_.is_cpu() ? std::max<int64_t>(0, recent_peak_memory_bytes() - resident_memory_bytes())
                       : 0;
  // Each new Gaussian counted twice: densification's copies of the parameters and moments, and
  // the allocator's slack, come on top of its steady cost.
  const int64_t growth = std::max<int64_t>(0, available - step_buffers) / (2 * kBytesPerGaussian);
  return std::min(configured, model_.size() + growth);
}

std::string Trainer::checkpoint_kept() const {
  return checkpoint_iteration_ >= 0
             ? fmt::format("the last good checkpoint (iteration {}) is kept in {}",
                           checkpoint_iteration_, checkpoint_path().string())
             : std::string("no checkpoint was written yet");
}

void Trainer::fail_out_of_memory() const {
  fail(
      "{} after iteration {}, training {} Gaussians; {}. The config's max_gaussians caps the "
      "model's growth.",
      current_exception_message(), iteration_, model_.size(), checkpoint_kept());
}

void Trainer::fail_diverged(int64_t iteration, double loss) const {
  fail(
      "training diverged at iteration {}: the {} stopped being finite (loss {}); {}. Lower the "
      "learning rates (or a run's depth loss weights, --li and --le), or check the input "
      "images and the starting model (--init-ply, random_extent).",
      iteration, std::isfinite(loss) ? "parameters" : "loss", loss, checkpoint_kept());
}

double Trainer::training_seconds() const {
  return seconds_before_ + run_watch_.seconds();
}

double Trainer::evaluate_psnr(const std::vector<TrainView>& views) const {
  torch::NoGradGuard no_grad;
  double sum = 0;
  for (const TrainView& view : views) {
    const raster::RenderOutput render =
        raster::render(raster::render_tensors(model_), raster::raster_camera<float>(view.camera),
                       setup_.background);
    sum += psnr(render.image, view.target);
  }
  return views.empty() ? 0 : sum / double(views.size());
}

bool Trainer::train_until_done_or_stopped(ProgressLog& log) {
  while (iteration_ < config_.iterations) {
    last_loss_ = step(iteration_ + 1);
    ++iteration_;
    const bool last = iteration_ == config_.iterations;
    // The parameters are checked after the optimizer step, and not every step (a reduction over
    // the whole model): a divergence shows within 100 iterations and never reaches the outputs.
    if ((iteration_ % 100 == 0 || last) && !model_is_finite(model_))
      fail_diverged(iteration_, last_loss_);
    std::optional<double> test_psnr;
    if (!setup_.test_views.empty() && config_.test_every > 0 &&
        (iteration_ % config_.test_every == 0 || last)) {
      test_psnr = evaluate_psnr(setup_.test_views);
      last_test_psnr_ = test_psnr;
    }
    // After the report: an opacity reset on the same iteration would make it read ~12 dB.
    refine(iteration_);
    const bool interrupted = interrupt_requested();
    log.record(iteration_, last_loss_, model_.size(), test_psnr, last || interrupted);
    if (last || interrupted ||
        (config_.checkpoint_every > 0 && iteration_ % config_.checkpoint_every == 0)) {
      log.flush();  // first: a resume keeps the rows up to its checkpoint and drops the rest
      save_checkpoint();
    }
    if (interrupted && !last) {  // on the last iteration, the run has finished: let it end
      fmt::print("interrupted: checkpoint of iteration {} saved to {}\n", iteration_,
                 checkpoint_path().string());
      return false;
    }
  }
  return true;
}

TrainSummary Trainer::run() {
  const InterruptScope interrupt_scope;
  // The peak densify_cap reads is this training's, not that of a run's earlier rows.
  restart_peak_memory();
  TrainSummary summary;
  ProgressLog log(setup_.output_dir / "train_log.csv", iteration_, config_.iterations,
                  config_.log_every, seconds_before_);
  write_cameras_json(cameras_path(), train_cameras_);
  run_watch_.restart();
  try {
    summary.interrupted = !train_until_done_or_stopped(log);
  } catch (...) {
    if (handling_out_of_memory()) fail_out_of_memory();
    throw;
  }
  // The finished run's moments are in its checkpoint: freed for the model files written next,
  // which copy the model (near the end of the memory, this is the peak).
  if (iteration_ == config_.iterations) optimizer_.reset();
  summary.seconds = training_seconds();
  summary.iterations = iteration_;
  summary.iterations_per_second = summary.seconds > 0 ? double(iteration_) / summary.seconds : 0;
  summary.final_loss = last_loss_;
  summary.test_psnr = last_test_psnr_;
  summary.gaussians = model_.size();
  return summary;
}

}  // namespace iesrgs::train
