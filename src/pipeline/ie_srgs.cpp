#include "pipeline/ie_srgs.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <optional>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/math.hpp"
#include "core/paths.hpp"
#include "core/progress.hpp"
#include "core/stopwatch.hpp"
#include "eval/lpips.hpp"
#include "eval/mask_agreement.hpp"
#include "io/atomic_file.hpp"
#include "io/file_digest.hpp"
#include "io/folder_lock.hpp"
#include "io/image_tensor.hpp"
#include "io/view_images.hpp"
#include "loss/texture_fusion.hpp"
#include "pipeline/diagnostics.hpp"
#include "pipeline/evaluate.hpp"
#include "pipeline/fusion_stage.hpp"
#include "pipeline/internal_stage.hpp"
#include "pipeline/render_views.hpp"
#include "pipeline/rows.hpp"
#include "pipeline/stage_record.hpp"
#include "pipeline/training_stage.hpp"
#include "train/session.hpp"

namespace iesrgs::pipeline {

namespace {

namespace fs = std::filesystem;
using loss::TextureGuidance;

// The `iesrgs external` command that makes the external stage a run with these options reads:
// the LR scene as the run loads it, and every option that changes the stage's images.
std::string external_stage_command(const RunOptions& o, int lr_downscale) {
  const ExternalOptions& external = o.external;
  std::string command = fmt::format("iesrgs external {} --downscale {} --scale {} --sr-model {}",
                                    shell_word(o.scene), lr_downscale, o.scale, external.sr_model);
  if (!external.sr_weights.empty()) command += " --sr-weights " + shell_word(external.sr_weights);
  if (external.tiles.tile != priors::sr::kDefaultTiles.tile)
    command += fmt::format(" --tile {}", external.tiles.tile);
  if (external.tiles.overlap != priors::sr::kDefaultTiles.overlap)
    command += fmt::format(" --tile-overlap {}", external.tiles.overlap);
  if (external.depth_model != "none") command += " --depth-model " + external.depth_model;
  if (!external.depth_weights.empty())
    command += " --depth-weights " + shell_word(external.depth_weights);
  if (const auto& background = o.scene_options.background)
    command +=
        fmt::format(" --background {},{},{}", (*background)[0], (*background)[1], (*background)[2]);
  if (o.scene_options.test_every != SceneOptions{}.test_every)
    command += fmt::format(" --test-every {}", o.scene_options.test_every);
  return command + " -o " + shell_word(o.output / "external");
}

// The HR rows take nearly all of a run's time: after each, where the run stands, with an ETA for
// the rows left to train at the pace of those trained so far (a row reused from the cache takes
// seconds, and is counted in neither).
class HrRowProgress {
 public:
  // Whether each HR row, in order, has to train: its stage is not cached.
  explicit HrRowProgress(std::vector<bool> trains) : trains_(std::move(trains)) {}

  void row_done(double seconds) {
    if (trains_[done_++]) {
      ++trained_;
      trained_seconds_ += seconds;
    }
    if (done_ == trains_.size()) return;
    const auto left =
        size_t(std::count(trains_.begin() + std::ptrdiff_t(done_), trains_.end(), true));
    fmt::print("HR rows: {} of {} done in {}{}\n", done_, trains_.size(),
               format_duration(watch_.seconds()),
               trained_ && left
                   ? fmt::format(", ETA {} for the rest",
                                 format_eta(trained_, trained_ + left, trained_seconds_))
                   : "");
  }

 private:
  std::vector<bool> trains_;
  size_t done_ = 0, trained_ = 0;
  double trained_seconds_ = 0;
  Stopwatch watch_;
};

class Pipeline {
 public:
  explicit Pipeline(const RunOptions& options);
  RunResult run();

 private:
  bool any_row(const std::function<bool(const RowSpec&)>& test) const;
  bool any_row(Source source) const;
  bool row_uses_internal(const RowSpec& row) const;
  bool rows_use_internal_references() const;
  void check_cached_inputs() const;
  void forget_earlier_results() const;
  void run_external_stages();
  void run_internal_stage();
  std::vector<Camera> hr_train_cameras() const;
  std::vector<Camera> test_cameras() const;
  loss::FusionWeights row_weights(const RowSpec& row) const;
  std::string row_label(const RowSpec& row) const;
  FusionSetup fusion_setup(const RowSpec& row, const loss::FusionWeights& weights) const;
  nlohmann::json row_params(const RowSpec& row, const loss::FusionWeights& weights) const;
  gs::GaussianModel initial_hr_model() const;
  void warn_if_lpips_unavailable() const;
  RowResult evaluate_row(const RowSpec& row, const gs::GaussianModel& model, const fs::path& dir);
  RowResult run_fusion_row(const RowSpec& row);
  // Whether `entry`, the row's result.json from an earlier run, is what these settings would
  // give.
  bool row_current(const RowSpec& row, const nlohmann::json& entry, bool internal_current) const;
  bool row_model_cached(const RowSpec& row) const;  // its HR model is trained for these settings
  fs::path row_dir(const std::string& id) const { return o_.output / "rows" / id; }
  // What this run scores against: the test views' digest and the LPIPS net.
  nlohmann::json evaluation() const;
  void keep_earlier_rows(RunResult& result) const;
  void write_fusion_diagnostics(const gs::GaussianModel& model, const FusionSetup& setup) const;
  void write_mask_agreement(const FusionSetup& setup) const;
  void say_truth_size_differs(size_t i, const Camera& camera) const;
  // The HR ground truth of training view i, (3, H, W); undefined when the run has none at
  // `camera`'s size.
  torch::Tensor train_truth(size_t i, const Camera& camera) const;
  // The oracle mask of training view i of `setup`, (H, W) float, as the internal share.
  torch::Tensor oracle_share(size_t i, const FusionSetup& setup) const;

  RunOptions o_;
  std::vector<std::string> rows_;
  Scene lr_scene_;
  std::optional<Scene> hr_scene_;
  std::unique_ptr<ViewImages> lr_images_, hr_images_;
  double threshold_;
  // What the internal model and the rows learn from and are scored against (split_digest),
  // computed once: every stage's record and every cached row's check needs it.
  std::string train_digest_, test_digest_;
  std::vector<ExternalView> external_, bicubic_;
  std::optional<InternalStage> internal_;
  nlohmann::json stages_ = nlohmann::json::object();
  // The metric every row is scored with, loaded at the first row scored (the weights are large).
  std::optional<eval::LoadedLpips> lpips_;
};

// The first view (of the training views, or of all) whose LR size times the scale is not its HR
// truth's: an LR size rounded, as a scale that does not divide the image size leaves it.
std::optional<size_t> first_rounded_view(const Scene& hr, const Scene& lr, int scale,
                                         bool training_only) {
  for (size_t i = 0; i < hr.cameras.size(); ++i) {
    if (training_only && hr.cameras[i].split != Split::Train) continue;
    const Intrinsics &high = hr.cameras[i].intrinsics, &low = lr.cameras[i].intrinsics;
    if (high.width != low.width * scale || high.height != low.height * scale) return i;
  }
  return std::nullopt;
}

// "at --downscale 1 this view is 64x64, which --scale 3 does not divide", for the i-th view.
std::string rounded_view_sizes(const Scene& hr, size_t i, int scale) {
  const Intrinsics& high = hr.cameras[i].intrinsics;
  return fmt::format("at --downscale {} this view is {}x{}, which --scale {} does not divide",
                     hr.downscale, high.width, high.height, scale);
}

// The mask-oracle row compares the references with the HR truth pixel by pixel, at the LR views'
// size times the scale: the truth must have that size. (Other rows render the test views at the
// truth's own size, whatever the scale.)
void require_scale_divides(const Scene& hr, const Scene& lr, int scale) {
  const std::optional<size_t> i = first_rounded_view(hr, lr, scale, true);
  if (!i) return;
  const Intrinsics& low = lr.cameras[*i].intrinsics;
  fail_file(hr.cameras[*i].image_path,
            fmt::format("{} (the LR view would be {}x{}, upscaled {}x{}), which the mask-oracle "
                        "row compares with it pixel by pixel; pick a scale or downscale that "
                        "divides the image size",
                        rounded_view_sizes(hr, *i, scale), low.width, low.height, low.width * scale,
                        low.height * scale));
}

// The HR rows train at the LR size times the scale, and their test views are scored at the
// truth's own size: said, for the first view where the two differ.
void warn_if_scale_rounds(const Scene& hr, const Scene& lr, int scale) {
  const std::optional<size_t> i = first_rounded_view(hr, lr, scale, false);
  if (!i) return;
  const Intrinsics &high = hr.cameras[*i].intrinsics, &low = lr.cameras[*i].intrinsics;
  spdlog::warn(
      "{}: {}: its LR view is {}x{} (rounded), so the HR models train at {}x{} and are scored at "
      "{}x{}; a scale or downscale that divides the image size keeps them equal",
      hr.cameras[*i].image_path.string(), rounded_view_sizes(hr, *i, scale), low.width, low.height,
      low.width * scale, low.height * scale, high.width, high.height);
}

Pipeline::Pipeline(const RunOptions& options) : o_(options), rows_(expand_rows(options.rows)) {
  if (o_.scale < 2) fail("--scale must be at least 2, got {}", o_.scale);
  o_.external.scale = o_.scale;
  // Also when no row of this run upscales: the folder's earlier rows that did are matched by it.
  resolve_sr_model(o_.external, any_row(Source::SuperResolved));
  SceneOptions lr_options = o_.scene_options;
  if (!o_.input_is_lr) {
    hr_scene_ = load_scene(o_.scene, o_.scene_options);
    hr_images_ = std::make_unique<ViewImages>(*hr_scene_);
    lr_options.downscale *= o_.scale;
  }
  lr_scene_ = load_scene(o_.scene, lr_options);
  refuse_output_in_scene_folder(o_.output, lr_scene_);
  if (lr_scene_.split(Split::Test).empty())
    fmt::print(
        "note: {} has no test views: the models are trained, but no test view is rendered or "
        "scored\n",
        lr_scene_.root.string());
  if (hr_scene_ && any_row([](const RowSpec& row) { return row.oracle_mask; }))
    require_scale_divides(*hr_scene_, lr_scene_, o_.scale);
  if (hr_scene_) warn_if_scale_rounds(*hr_scene_, lr_scene_, o_.scale);
  require_trainable_views(lr_scene_);
  lr_images_ = std::make_unique<ViewImages>(lr_scene_);
  threshold_ = o_.threshold >= 0     ? o_.threshold
               : lr_scene_.synthetic ? loss::kDiscrepancyThresholdSynthetic
                                     : loss::kDiscrepancyThresholdReal;
  if (o_.input_is_lr && any_row(RowSpec::needs_truth))
    fail(
        "the hr and mask-oracle rows need HR images, which a low-resolution input "
        "(--input-is-lr) lacks");
  train_digest_ = split_digest(*lr_images_, Split::Train);
  test_digest_ = split_digest(hr_images_ ? *hr_images_ : *lr_images_, Split::Test);
  warn_if_lpips_unavailable();
}

// Before the trainings, not after the first of them: the table will show "-" for LPIPS. The
// internal stage alone scores nothing.
void Pipeline::warn_if_lpips_unavailable() const {
  if (!hr_images_ || o_.lpips == "none" || o_.only == StageSelection::Internal) return;
  const eval::LpipsNet net = eval::parse_lpips_net(o_.lpips);
  if (const auto missing = eval::lpips_unavailable_reason(net, eval::default_lpips_weights(net)))
    spdlog::warn("LPIPS ({}) unavailable: {}", o_.lpips, *missing);
}

bool Pipeline::any_row(const std::function<bool(const RowSpec&)>& test) const {
  for (const std::string& id : rows_)
    if (test(row_spec(id))) return true;
  return false;
}

bool Pipeline::any_row(Source source) const {
  return any_row([source](const RowSpec& row) { return row.source == source; });
}

bool Pipeline::row_uses_internal(const RowSpec& row) const {
  const loss::FusionWeights weights = row_weights(row);
  return o_.init == "internal" || row.source == Source::Internal ||
         weights.texture != TextureGuidance::External || weights.internal_depth > 0;
}

bool Pipeline::rows_use_internal_references() const {
  return any_row([this](const RowSpec& row) { return row_uses_internal(row); });
}

void Pipeline::check_cached_inputs() const {
  const auto require = [](bool current, const fs::path& dir, const char* stage,
                          const std::string& runners) {
    if (!current)
      fail_file(dir, fmt::format("the {} stage here is missing, unfinished, or made from other "
                                 "images or settings than these; {} with the same scene and "
                                 "options makes it",
                                 stage, runners));
  };
  if (any_row(Source::SuperResolved))
    require(external_stage_current(lr_scene_, *lr_images_, o_.external, o_.output / "external"),
            o_.output / "external", "external",
            external_stage_command(o_, lr_scene_.downscale) + " or iesrgs run");
  if (rows_use_internal_references())
    require(internal_stage_current(lr_scene_, train_digest_, o_.internal_config, o_.scale,
                                   o_.output / "internal"),
            o_.output / "internal", "internal", "iesrgs internal or iesrgs run");
}

// An interrupted run leaves no table, row scores or test renders of an earlier one that read as
// its own: the table is written again when the run finishes, each row's scores and test views
// when the row is scored. `iesrgs internal` scores nothing, so it does this only when it makes
// the internal model again, whose row's scores and renders then show a model that is gone. The
// other rows' scores stay, for keep_earlier_rows.
void Pipeline::forget_earlier_results() const {
  const bool scoring = o_.only != StageSelection::Internal;
  // The model alone: the check of the SR-splatting renders decodes every one of them, which
  // run_internal_stage does anyway.
  const bool internal_changes =
      (!scoring || rows_use_internal_references()) &&
      !internal_model_current(lr_scene_, train_digest_, o_.internal_config, o_.output / "internal");
  if (!scoring && !internal_changes) return;
  keep_table_scores_in_rows(o_.output);
  for (const char* table : {"results.md", "results.csv", "results.json"})
    remove_earlier_output(o_.output / table, "left by an earlier run");
  const auto forget_row = [this](const std::string& id) {
    remove_earlier_output(row_dir(id) / kRowResultFile, "left by an earlier run");
    mark_render_stale(row_dir(id) / "test");
  };
  if (internal_changes) forget_row("internal");
  if (scoring)
    for (const std::string& id : rows_) forget_row(id);
  // Written whole again after the ie-srgs row; a stopped run would leave an earlier run's
  // pictures, of other settings, or some of each.
  if (scoring && std::find(rows_.begin(), rows_.end(), "ie-srgs") != rows_.end()) {
    std::error_code ec;
    fs::remove_all(o_.output / "diagnostics", ec);
    if (ec)
      fail_file(o_.output / "diagnostics",
                "left by an earlier run, and cannot be removed: " + ec.message());
  }
}

// The stages' time is what computing their views took when it ran, as a reused training counts
// the time it took.
void Pipeline::run_external_stages() {
  ExternalOptions options = o_.external;
  if (any_row(Source::SuperResolved))
    external_ = run_external_stage(lr_scene_, *lr_images_, options, o_.output / "external");
  if (any_row(Source::Bicubic)) {
    options.sr_model = "bicubic";
    options.sr_weights.clear();
    options.depth_model = "none";
    bicubic_ = run_external_stage(lr_scene_, *lr_images_, options, o_.output / "bicubic");
  }
  double seconds = 0;
  for (const auto* views : {&external_, &bicubic_})
    for (const ExternalView& view : *views) seconds += view.seconds;
  stages_["external_seconds"] = seconds;
}

void Pipeline::run_internal_stage() {
  internal_ = pipeline::run_internal_stage(lr_scene_, train_digest_, *lr_images_,
                                           o_.internal_config, o_.scale, o_.output / "internal");
  stages_["internal_training_seconds"] = internal_->training.seconds;
  stages_["sr_splatting_seconds"] = stage_seconds(internal_->sr_dir);
}

std::vector<Camera> Pipeline::hr_train_cameras() const {
  std::vector<Camera> cameras;
  for (const Camera* camera : lr_scene_.split(Split::Train))
    cameras.push_back(camera->scaled(o_.scale));
  return cameras;
}

std::vector<Camera> Pipeline::test_cameras() const {
  std::vector<Camera> cameras;
  if (hr_scene_) {
    for (const Camera* camera : hr_scene_->split(Split::Test)) cameras.push_back(*camera);
  } else {
    for (const Camera* camera : lr_scene_.split(Split::Test))
      cameras.push_back(camera->scaled(o_.scale));
  }
  return cameras;
}

loss::FusionWeights Pipeline::row_weights(const RowSpec& row) const {
  loss::FusionWeights weights = o_.weights;
  if (std::string(row.id) != "ie-srgs") {
    weights.texture = row.texture;
    if (!row.internal_depth) weights.internal_depth = 0;
    if (!row.external_depth) weights.external_depth = 0;
  }
  if (o_.external.depth_model == "none") weights.external_depth = 0;
  return weights;
}

// The ie-srgs row takes --texture: off the mask, its label says what supervised it instead. The
// row that adds E_depth says when there is none, since it then trains as external only.
std::string Pipeline::row_label(const RowSpec& row) const {
  const TextureGuidance texture = row_weights(row).texture;
  if (texture != row.texture)
    return fmt::format("IE-SRGS, {} texture (no mask)", loss::texture_guidance_name(texture));
  if (std::string(row.id) == "external-depth" && o_.external.depth_model == "none")
    return fmt::format("{} (off: no --depth-model)", row.label);
  return row.label;
}

FusionSetup Pipeline::fusion_setup(const RowSpec& row, const loss::FusionWeights& weights) const {
  FusionSetup setup;
  setup.weights = weights;
  setup.background = lr_scene_.background;
  setup.scene_extent = lr_scene_.normalization().radius;
  if (hr_scene_)
    setup.test_views = train::load_views(*hr_scene_, Split::Test, *hr_images_,
                                         size_t(o_.fusion_config.test_views));
  if (row.source == Source::HighRes) {
    for (const Camera* camera : hr_scene_->split(Split::Train)) {
      setup.cameras.push_back(*camera);
      loss::FusionTargets targets;
      targets.external_image = to_tensor(*hr_images_->rgb(*camera))[0];
      targets.internal_share =
          loss::internal_share(TextureGuidance::External, {}, targets.external_image, 0);
      setup.targets.push_back(std::move(targets));
    }
    return setup;
  }
  setup.cameras = hr_train_cameras();
  const std::vector<ExternalView>& external = row.source == Source::Bicubic ? bicubic_ : external_;
  if (external.size() != setup.cameras.size())
    fail("the external stage made {} views for {} HR training views", external.size(),
         setup.cameras.size());
  for (size_t i = 0; i < setup.cameras.size(); ++i) {
    const std::string& name = setup.cameras[i].name;
    // Each view's references are its own: a view trained on another's would still train.
    if (external[i].name != name)
      fail("HR training view {} is {}, its external references {}'s", i, name, external[i].name);
    ReferenceFiles files{external[i].image, external[i].depth, {}, {}};
    if (internal_) {
      const RenderedViewFiles rendered = rendered_view_files(internal_->sr_dir, name);
      files.internal_image = rendered.rgb;
      files.internal_depth = rendered.depth_npy;
    }
    setup.targets.push_back(load_fusion_targets(files, setup.cameras[i], weights, threshold_));
    if (row.oracle_mask) setup.targets.back().internal_share = oracle_share(i, setup);
  }
  return setup;
}

nlohmann::json Pipeline::row_params(const RowSpec& row, const loss::FusionWeights& weights) const {
  nlohmann::json params = {{"row", row.id},
                           {"points", points_digest(lr_scene_.points)},
                           {"lr_downscale", lr_scene_.downscale},
                           {"scale", o_.scale},
                           {"texture", loss::texture_guidance_name(weights.texture)},
                           {"dssim_weight", weights.dssim_weight},
                           {"internal_depth", weights.internal_depth},
                           {"external_depth", weights.external_depth},
                           {"init", o_.init},
                           {"train_views", train_digest_},
                           {"test_views", test_digest_}};
  if (row.source == Source::SuperResolved)
    params["external"] = {{"sr_model", o_.external.sr_model},
                          {"depth_model", o_.external.depth_model}};
  // T shapes only the discrepancy mask; the oracle mask comes from the HR truth instead.
  if (weights.texture == TextureGuidance::Masked && !row.oracle_mask)
    params["threshold"] = threshold_;
  if (RowSpec::needs_truth(row)) params["hr_train_views"] = split_digest(*hr_images_, Split::Train);
  // The stage's record holds a content fingerprint per view: it changes with any reference.
  if (row.source == Source::SuperResolved || row.source == Source::Bicubic)
    params["references"] = file_digest(
        o_.output / (row.source == Source::Bicubic ? "bicubic" : "external") / "external.json");
  // The internal model's recorded training time tells which model the row's references came from.
  if (row_uses_internal(row))
    params["internal_model_seconds"] = stage_seconds(o_.output / "internal");
  return params;
}

gs::GaussianModel Pipeline::initial_hr_model() const {
  if (o_.init == "internal") {
    gs::GaussianModel model = internal_->training.model.clone();  // rows later still need it
    model.active_sh_degree = 0;  // the HR schedule raises the SH degree again
    return model;
  }
  return train::initial_model(hr_scene_ ? *hr_scene_ : lr_scene_, o_.fusion_config, {});
}

RowResult Pipeline::evaluate_row(const RowSpec& row, const gs::GaussianModel& model,
                                 const fs::path& dir) {
  if (hr_images_ && !lpips_) lpips_ = eval::load_default_lpips(o_.lpips);
  const Stopwatch watch;
  const Evaluation evaluation =
      render_and_evaluate(model, test_cameras(), o_.scene_options.test_every, lr_scene_.background,
                          hr_images_.get(), lpips_ ? *lpips_ : eval::LoadedLpips{}, dir / "test");
  stages_["evaluation_seconds"][row.id] = watch.seconds();
  RowResult result;
  result.id = row.id;
  result.label = row_label(row);
  result.evaluated = !evaluation.report.views.empty();
  if (result.evaluated) result.mean = evaluation.report.mean();
  result.fps = frames_per_second(evaluation.seconds_per_view);
  return result;
}

RowResult Pipeline::run_fusion_row(const RowSpec& row) {
  const loss::FusionWeights weights = row_weights(row);
  const fs::path dir = row_dir(row.id);
  FusionSetup setup = fusion_setup(row, weights);
  const FusionSetup diagnostics_setup = std::string(row.id) == "ie-srgs" ? setup : FusionSetup{};
  const StageResult stage =
      run_fusion_stage(std::move(setup), o_.fusion_config, row_params(row, weights), dir,
                       [this] { return initial_hr_model(); });
  stages_["fusion_seconds"][row.id] = stage.seconds;
  if (!diagnostics_setup.cameras.empty()) {
    write_fusion_diagnostics(stage.model, diagnostics_setup);
    write_mask_agreement(diagnostics_setup);
  }
  RowResult result = evaluate_row(row, stage.model, dir);
  result.train_seconds = stage.seconds;
  return result;
}

void Pipeline::write_fusion_diagnostics(const gs::GaussianModel& model,
                                        const FusionSetup& setup) const {
  std::vector<DiagnosticView> views;
  for (size_t i : evenly_spaced(setup.cameras.size(), size_t(std::max(o_.diagnostic_views, 0)))) {
    const Camera& camera = setup.cameras[i];
    const RenderedView render = render_view(model, camera, setup.background);
    views.push_back({camera.name, setup.targets[i].external_image, setup.targets[i].internal_image,
                     render.image, render.depth, train_truth(i, camera)});
  }
  write_diagnostics(o_.output / "diagnostics", views, threshold_);
}

torch::Tensor Pipeline::oracle_share(size_t i, const FusionSetup& setup) const {
  const Camera& camera = setup.cameras[i];
  const torch::Tensor truth = train_truth(i, camera);
  if (!truth.defined())
    fail_file(hr_scene_ ? hr_scene_->split(Split::Train)[i]->image_path : camera.image_path,
              fmt::format("the mask-oracle row needs the HR truth of view {} at the HR camera's "
                          "size, {}x{}",
                          camera.name, camera.intrinsics.width, camera.intrinsics.height));
  const loss::FusionTargets& targets = setup.targets[i];
  return eval::oracle_mask(targets.internal_image, targets.external_image, truth).to(torch::kFloat);
}

torch::Tensor Pipeline::train_truth(size_t i, const Camera& camera) const {
  if (!hr_scene_) return {};
  const Camera& truth_camera = *hr_scene_->split(Split::Train)[i];
  if (truth_camera.intrinsics.width != camera.intrinsics.width ||
      truth_camera.intrinsics.height != camera.intrinsics.height)
    return {};
  return to_tensor(*hr_images_->rgb(truth_camera))[0];
}

// The truth is there but not at the HR camera's size (an LR size that --scale does not divide the
// truth's by): the diagnostics that compare with it are left out, and the user is told why.
void Pipeline::say_truth_size_differs(size_t i, const Camera& camera) const {
  const Intrinsics& truth = hr_scene_->split(Split::Train)[i]->intrinsics;
  fmt::print(
      "diagnostics: view {}'s HR truth is {}x{}, the HR training view {}x{} (its LR size x "
      "{}); mask_check, truth and mask_agreement.json are left out\n",
      camera.name, truth.width, truth.height, camera.intrinsics.width, camera.intrinsics.height,
      o_.scale);
}

void Pipeline::write_mask_agreement(const FusionSetup& setup) const {
  const fs::path path = o_.output / "diagnostics" / "mask_agreement.json";
  // Without both references and the truth there is nothing to check, and an earlier run's
  // check would pass for this run's.
  std::error_code ignored;
  fs::remove(path, ignored);
  eval::MaskCounts counts;
  for (size_t i = 0; i < setup.cameras.size(); ++i) {
    const loss::FusionTargets& targets = setup.targets[i];
    if (!targets.internal_image.defined()) return;
    const torch::Tensor truth = train_truth(i, setup.cameras[i]);
    if (!truth.defined()) {
      if (hr_scene_) say_truth_size_differs(i, setup.cameras[i]);
      return;
    }
    counts += eval::mask_counts(targets.internal_image, targets.external_image, truth, threshold_);
  }
  const nlohmann::json json = {{"threshold", threshold_},
                               {"views", setup.cameras.size()},
                               {"mask_share", counts.mask_share()},
                               {"truth_mask_share", counts.truth_mask_share()},
                               {"precision", counts.precision()},
                               {"recall", counts.recall()},
                               {"iou", counts.iou()},
                               {"internal_closer_share", counts.internal_closer_share()},
                               {"psnr_external", counts.external_psnr()},
                               {"psnr_internal", counts.internal_psnr()},
                               {"psnr_fused", counts.fused_psnr()},
                               {"oracle_mask_share", counts.oracle_mask_share()},
                               {"psnr_oracle", counts.oracle_psnr()}};
  write_file_atomically(path, json.dump(2) + "\n");
  fmt::print(
      "mask M on {:.2f}% of the training pixels, the truth's mask G on {:.2f}%: IoU {:.3f}, "
      "precision {:.3f}, recall {:.3f}; the internal image is the closer one at {:.1f}% of M "
      "({})\n"
      "references against the HR truth: E_image {:.2f} dB, I_image {:.2f} dB, fused by M {:.2f} "
      "dB, by the oracle mask ({:.1f}% of the pixels) {:.2f} dB\n",
      100 * counts.mask_share(), 100 * counts.truth_mask_share(), counts.iou(), counts.precision(),
      counts.recall(), 100 * counts.internal_closer_share(), path.string(), counts.external_psnr(),
      counts.internal_psnr(), counts.fused_psnr(), 100 * counts.oracle_mask_share(),
      counts.oracle_psnr());
}

RunResult Pipeline::run() {
  const Stopwatch watch;
  if (o_.only == StageSelection::Fusion) check_cached_inputs();
  forget_earlier_results();
  if (o_.only != StageSelection::Internal) run_external_stages();
  if (rows_use_internal_references() || o_.only == StageSelection::Internal) run_internal_stage();
  if (o_.only == StageSelection::Internal) return {{}, stages_, {}};

  RunResult result;
  std::vector<bool> hr_rows_to_train;
  for (const std::string& id : rows_)
    if (const RowSpec& row = row_spec(id); row.source != Source::Internal)
      hr_rows_to_train.push_back(!row_model_cached(row));
  HrRowProgress progress(std::move(hr_rows_to_train));
  for (size_t i = 0; i < rows_.size(); ++i) {
    const RowSpec& row = row_spec(rows_[i]);
    fmt::print("\n== row {}/{} {}: {} ==\n", i + 1, rows_.size(), row.id, row_label(row));
    const fs::path dir = row_dir(row.id);
    if (row.source != Source::Internal) {
      const Stopwatch row_watch;
      result.rows.push_back(run_fusion_row(row));
      progress.row_done(row_watch.seconds());
    } else {
      result.rows.push_back(evaluate_row(row, internal_->training.model, dir));
      result.rows.back().train_seconds = internal_->training.seconds;
    }
    write_row_result(dir, result.rows.back(), evaluation());
  }
  result.evaluation = evaluation();
  keep_earlier_rows(result);
  stages_["total_seconds_this_run"] = watch.seconds();
  result.stages = stages_;
  return result;
}

bool Pipeline::row_current(const RowSpec& row, const nlohmann::json& entry,
                           bool internal_current) const {
  if (RowSpec::needs_truth(row) && !hr_images_) return false;
  if (row_uses_internal(row) && !internal_current) return false;
  // The entry must score the model its stage holds now, which its recorded training time names:
  // a later run may have trained the internal model again, or a row, and stopped before writing
  // the table.
  const bool internal = row.source == Source::Internal;
  const fs::path dir = internal ? o_.output / "internal" : row_dir(row.id);
  if (entry.value("train_seconds", -1.0) != stage_seconds(dir)) return false;
  return internal || row_model_cached(row);
}

bool Pipeline::row_model_cached(const RowSpec& row) const {
  return training_stage_current(row_dir(row.id), row_params(row, row_weights(row)),
                                o_.fusion_config);
}

nlohmann::json Pipeline::evaluation() const {
  // "lpips" is the net asked for, which earlier rows are matched by; the status says whether it
  // was computed.
  nlohmann::json evaluation = {{"test_views", test_digest_}, {"lpips", o_.lpips}};
  if (lpips_) evaluation["lpips_status"] = lpips_->status;
  return evaluation;
}

// A rerun with fewer rows keeps the other rows scored in this folder, whichever run scored them,
// as long as their cached stage is still the one these settings would reuse and they were scored
// against the same test views; rows trained under other settings are left out, and so are scores
// a damaged file garbled. An LPIPS taken with another network is left out.
void Pipeline::keep_earlier_rows(RunResult& result) const {
  // Asked at most once: the check decodes every cached render. A stage this run used is current.
  std::optional<bool> internal_current;
  if (internal_) internal_current = true;
  for (const std::string& id : expand_rows({"all"})) {
    if (std::find(rows_.begin(), rows_.end(), id) != rows_.end()) continue;
    const fs::path file = row_dir(id) / kRowResultFile;
    if (!fs::exists(file)) continue;
    // A row scored here whose record was damaged since (or copied from another row's): a silent
    // gap in the table would read as a row never run.
    const auto warn_damaged = [&] {
      spdlog::warn("{}: damaged, so the table leaves the {} row out; --rows {} scores it again",
                   file.string(), id, id);
    };
    const nlohmann::json earlier = read_stage_record(file);
    const nlohmann::json scored = earlier.value("evaluation", nlohmann::json());
    const nlohmann::json entry = earlier.value("row", nlohmann::json());
    if (!scored.is_object() || !entry.is_object() || entry.value("row", nlohmann::json()) != id) {
      warn_damaged();
      continue;
    }
    const auto same = [&](const char* key) {
      return scored.value(key, nlohmann::json()) == result.evaluation[key];
    };
    if (!same("test_views")) continue;
    try {
      const RowSpec& row = row_spec(id);
      if (!internal_current)
        internal_current = internal_stage_current(lr_scene_, train_digest_, o_.internal_config,
                                                  o_.scale, o_.output / "internal");
      if (!row_current(row, entry, *internal_current)) continue;
      result.rows.push_back(earlier_row(row, row_label(row), entry));
      if (!same("lpips")) result.rows.back().mean.lpips.reset();
    } catch (const nlohmann::json::exception&) {
      warn_damaged();  // a field of another type than the run writes
    }
  }
  std::stable_sort(result.rows.begin(), result.rows.end(), [](const auto& a, const auto& b) {
    return table_position(a.id) < table_position(b.id);
  });
}

}  // namespace

RunResult run_ie_srgs(const RunOptions& options) {
  // Between views and iterations, every stage stops where a rerun resumes.
  const InterruptScope interrupts;
  Pipeline pipeline(options);
  stop_if_interrupted("loading the scene");
  // Taken once the scenes have loaded, so that a run refused for its input leaves no folder.
  const FolderLock lock(options.output);
  RunResult result = pipeline.run();
  if (result.rows.empty()) return result;
  write_results(options.output, result);
  fmt::print("\n{}\nwrote {}\n", results_markdown(result),
             (options.output / "results.md").string());
  return result;
}

}  // namespace iesrgs::pipeline
