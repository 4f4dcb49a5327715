#include "gs/densify.hpp"

#include <cmath>

#include "core/error.hpp"

namespace iesrgs::gs {

namespace {

using torch::Tensor;

constexpr int kSplitSamples = 2;
constexpr double kSplitScaleDivisor = 0.8 * kSplitSamples;  // 3DGS: scale / (0.8 * N)

void check_rows(const Tensor& t, int64_t n, const char* name) {
  if (!t.defined() || t.dim() == 0 || t.size(0) != n)
    fail("densification statistics: {} does not have {} rows", name, n);
}

// (M, 3, 3) rotation matrices of (M, 4) quaternions w x y z, normalized first.
Tensor rotation_matrices(const Tensor& quats) {
  const Tensor q = quats / quats.norm(2, 1, true);
  const Tensor w = q.select(1, 0), x = q.select(1, 1), y = q.select(1, 2), z = q.select(1, 3);
  return torch::stack({1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                       2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                       2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)},
                      1)
      .view({-1, 3, 3});
}

Tensor max_scale(const GaussianModel& model) {
  return std::get<0>(model.log_scales.detach().exp().max(1));
}

// New Gaussians to append, one tensor per parameter plus their 3D filter.
struct NewRows {
  std::array<Tensor, kParamCount> params;
  Tensor filter_3d;
};

NewRows copies_of(const GaussianModel& model, const Tensor& mask) {
  NewRows rows;
  for (int p = 0; p < kParamCount; ++p)
    rows.params[p] = model.param(Param(p)).detach().index({mask});
  if (model.filter_3d.defined()) rows.filter_3d = model.filter_3d.index({mask});
  return rows;
}

// Each masked Gaussian becomes two samples drawn from itself, with scales / 1.6.
NewRows split_children(const GaussianModel& model, const Tensor& mask) {
  NewRows parents = copies_of(model, mask);
  NewRows rows;
  for (int p = 0; p < kParamCount; ++p) {
    std::vector<int64_t> repeats(parents.params[p].dim(), 1);
    repeats[0] = kSplitSamples;
    rows.params[p] = parents.params[p].repeat(repeats);
  }
  if (parents.filter_3d.defined()) rows.filter_3d = parents.filter_3d.repeat({kSplitSamples});
  Tensor& log_scales = rows.params[int(Param::LogScales)];
  // Drawn by the CPU generator on every device: checkpoints keep its state, so a resumed run
  // splits as the uninterrupted one, and a GPU run draws what a CPU run draws.
  const Tensor noise = torch::randn(log_scales.sizes(), log_scales.options().device(torch::kCPU));
  const Tensor offsets = noise.to(log_scales.device()) * log_scales.exp();
  const Tensor rotations = rotation_matrices(rows.params[int(Param::Quats)]);
  rows.params[int(Param::Means)] += torch::bmm(rotations, offsets.unsqueeze(2)).squeeze(2);
  // In log space: an axis whose exp underflows to 0 would otherwise get log(0).
  log_scales = log_scales - std::log(kSplitScaleDivisor);
  return rows;
}

void append_rows(GaussianModel& model, GaussianOptimizer& optimizer, const NewRows& rows) {
  const int64_t count = rows.params[0].size(0);
  for (int p = 0; p < kParamCount; ++p)
    model.set_param(Param(p), torch::cat({model.param(Param(p)).detach(), rows.params[p]}));
  if (model.filter_3d.defined()) model.filter_3d = torch::cat({model.filter_3d, rows.filter_3d});
  optimizer.append_rows(count);
}

void keep_rows(GaussianModel& model, GaussianOptimizer& optimizer, const Tensor& keep) {
  for (int p = 0; p < kParamCount; ++p)
    model.set_param(Param(p), model.param(Param(p)).detach().index({keep}));
  if (model.filter_3d.defined()) model.filter_3d = model.filter_3d.index({keep}).contiguous();
  optimizer.keep_rows(keep);
}

Tensor mean_gradient(const DensifyStats& stats, GradientSource source) {
  const Tensor& sum = source == GradientSource::Absolute ? stats.abs_grad_sum : stats.grad_sum;
  return torch::where(stats.count > 0, sum / stats.count.clamp_min(1), torch::zeros_like(sum));
}

// Narrows `selected` to its `budget` Gaussians of the largest gradient when it holds more;
// returns how many it left out.
int64_t keep_within_budget(Tensor& selected, const Tensor& gradient, int64_t budget) {
  const Tensor candidates = selected.nonzero().squeeze(1);
  const int64_t surplus = candidates.size(0) - budget;
  if (surplus <= 0) return 0;
  const Tensor best = std::get<1>(gradient.index({candidates}).topk(budget));
  selected = torch::zeros_like(selected);
  selected.index_put_({candidates.index({best})}, true);
  return surplus;
}

Tensor prune_mask(const GaussianModel& model, const DensifyStats& stats,
                  const DensifyOptions& options, double scene_extent) {
  Tensor mask = torch::sigmoid(model.opacity_logits.detach()) < options.min_opacity;
  if (options.max_screen_size > 0) mask = mask | (stats.max_radii > options.max_screen_size);
  if (options.max_world_size > 0)
    mask = mask | (max_scale(model) > options.max_world_size * scene_extent);
  return mask;
}

}  // namespace

DensifyStats DensifyStats::zeros(int64_t n, torch::Device device) {
  const auto options = torch::TensorOptions().device(device);
  return {torch::zeros({n}, options), torch::zeros({n}, options), torch::zeros({n}, options),
          torch::zeros({n}, options)};
}

void DensifyStats::to(torch::Device device) {
  for (Tensor* t : {&grad_sum, &abs_grad_sum, &count, &max_radii}) *t = t->to(device);
}

void DensifyStats::accumulate(const std::vector<ViewStatistics>& views) {
  const int64_t n = count.size(0);
  for (const ViewStatistics& view : views) {
    check_rows(view.radii, n, "radii");
    check_rows(view.viewspace_grad, n, "viewspace gradient");
    const Tensor visible = (view.radii > 0).to(torch::kFloat32);
    grad_sum += view.viewspace_grad.norm(2, 1) * visible;
    if (view.viewspace_abs_grad.defined()) {
      check_rows(view.viewspace_abs_grad, n, "absolute viewspace gradient");
      abs_grad_sum += view.viewspace_abs_grad.norm(2, 1) * visible;
    }
    count += visible;
    max_radii = torch::maximum(max_radii, view.radii.to(torch::kFloat32) * visible);
  }
}

void DensifyStats::save(torch::serialize::OutputArchive& archive) const {
  archive.write("densify/grad_sum", grad_sum);
  archive.write("densify/abs_grad_sum", abs_grad_sum);
  archive.write("densify/count", count);
  archive.write("densify/max_radii", max_radii);
}

void DensifyStats::load(torch::serialize::InputArchive& archive, int64_t n) {
  DensifyStats loaded;
  archive.read("densify/grad_sum", loaded.grad_sum);
  archive.read("densify/abs_grad_sum", loaded.abs_grad_sum);
  archive.read("densify/count", loaded.count);
  archive.read("densify/max_radii", loaded.max_radii);
  for (const Tensor* t : {&loaded.grad_sum, &loaded.abs_grad_sum, &loaded.count, &loaded.max_radii})
    if (t->sizes() != c10::IntArrayRef{n} || t->scalar_type() != torch::kFloat32)
      fail("densification statistics: stored accumulators do not have {} rows", n);
  *this = loaded;
}

DensifyCounts densify_and_prune(GaussianModel& model, GaussianOptimizer& optimizer,
                                DensifyStats& stats, const DensifyOptions& options,
                                double scene_extent) {
  torch::NoGradGuard no_grad;
  const int64_t n = model.size();
  const Tensor gradient = mean_gradient(stats, options.source);
  Tensor selected = gradient >= options.grad_threshold;
  DensifyCounts counts;
  if (options.max_gaussians > 0)  // each clone and each split adds one Gaussian
    counts.held_back =
        keep_within_budget(selected, gradient, std::max<int64_t>(0, options.max_gaussians - n));
  const Tensor large = max_scale(model) > options.percent_dense * scene_extent;
  const Tensor clone = selected & ~large, split = selected & large;
  counts.cloned = clone.sum().item<int64_t>();
  counts.split = split.sum().item<int64_t>();

  // Rows as 3DGS orders them: originals, their clones, then the split children; split parents go.
  const NewRows clones = copies_of(model, clone);
  const NewRows children = split_children(model, split);
  append_rows(model, optimizer, clones);
  append_rows(model, optimizer, children);
  const int64_t added = model.size() - n;
  stats.max_radii =
      torch::cat({stats.max_radii, torch::zeros({added}, stats.max_radii.options())});  // unseen
  const Tensor parent_gone = torch::cat({split, torch::zeros({added}, split.options())});

  const Tensor keep = ~(parent_gone | prune_mask(model, stats, options, scene_extent));
  counts.pruned = model.size() - keep.sum().item<int64_t>() - counts.split;
  keep_rows(model, optimizer, keep);
  stats = DensifyStats::zeros(model.size(), model.means.device());
  return counts;
}

void reset_opacity(GaussianModel& model, GaussianOptimizer& optimizer) {
  torch::NoGradGuard no_grad;
  // Mip-Splatting caps the opacity the renderer draws, opacity times the 3D filter's gain
  // sqrt(prod(s^2 / (s^2 + f^2))), at 0.01: the stored opacity at min(opacity, 0.01 / gain). The
  // gain is taken in log space because a Gaussian flattened far below its filter has a gain
  // that underflows to 0 in floats, where 0.01 / gain would be NaN; its cap is then 1 - 1e-6.
  const Tensor logits = model.opacity_logits.detach();
  Tensor log_gain = torch::zeros_like(logits);
  if (model.filter_3d.defined()) {
    const Tensor log_ratio = 2 * (model.filter_3d.log().unsqueeze(1) - model.log_scales.detach());
    log_gain = -0.5 * torch::softplus(log_ratio).sum(1);
  }
  const Tensor cap = torch::logit((std::log(0.01) - log_gain).exp(), 1e-6);
  model.set_param(Param::OpacityLogits, torch::minimum(logits, cap));
  optimizer.reset_moments(Param::OpacityLogits);
}

}  // namespace iesrgs::gs
