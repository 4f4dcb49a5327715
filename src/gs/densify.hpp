#pragma once
// Adaptive density control of 3DGS / Mip-Splatting: screen-space gradient statistics gathered
// from every rendered view, then clone, split and prune, and the periodic opacity reset. The
// model's rows and the optimizer's moments always change together.
#include <torch/serialize/archive.h>
#include <torch/types.h>

#include <vector>

#include "gs/model.hpp"
#include "gs/optimizer.hpp"

namespace iesrgs::gs {

// What one rendered view reports per Gaussian: the .grad() of its viewspace probes ((N, 2)
// each) and its radii ((N) int32, 0 where not drawn).
struct ViewStatistics {
  torch::Tensor viewspace_grad;
  torch::Tensor viewspace_abs_grad;
  torch::Tensor radii;
};

// Absolute: AbsGS's sums of absolute per-pixel gradients in place of the norm of their sum, as
// gsplat's absgrad. They run larger: gsplat pairs them with a threshold near 8e-4, not 2e-4.
enum class GradientSource { Viewspace, Absolute };

struct DensifyOptions {
  double grad_threshold = 2e-4;
  GradientSource source = GradientSource::Viewspace;
  double percent_dense = 0.01;  // clone below, split above this fraction of the extent
  double min_opacity = 0.005;
  float max_screen_size = 0;  // prune splats drawn larger (max radius, pixels); 0: off
  double max_world_size = 0;  // prune splats larger than this x the extent; 0: off
  // Clones and splits stop at this many Gaussians, those of the largest gradients going first;
  // 0: no cap.
  int64_t max_gaussians = 0;
};

// Per-Gaussian accumulators between two densification steps, as 3DGS's xyz_gradient_accum,
// denom and max_radii2D (all (N) float).
struct DensifyStats {
  torch::Tensor grad_sum, abs_grad_sum, count, max_radii;

  static DensifyStats zeros(int64_t n, torch::Device device = torch::kCPU);
  // Moves the accumulators to `device`, where the model's parameters are.
  void to(torch::Device device);
  // Adds each view's gradient norms where that view drew the Gaussian, so all K views of a
  // multi-view iteration count.
  void accumulate(const std::vector<ViewStatistics>& views);

  void save(torch::serialize::OutputArchive& archive) const;
  // Throws Error unless the stored accumulators hold `n` rows.
  void load(torch::serialize::InputArchive& archive, int64_t n);
};

struct DensifyCounts {
  int64_t cloned = 0, split = 0, pruned = 0;
  int64_t held_back = 0;  // selected, but neither cloned nor split because of max_gaussians
};

// Clones small Gaussians and splits large ones whose mean gradient reaches the threshold, then
// prunes transparent and (when enabled) oversized ones, then zeroes the stats. Split samples
// come from torch's default CPU generator, whatever the model's device. The reference zeroes the
// screen radii before its size check, which disables it; here it uses the radii gathered since the
// last densification.
DensifyCounts densify_and_prune(GaussianModel& model, GaussianOptimizer& optimizer,
                                DensifyStats& stats, const DensifyOptions& options,
                                double scene_extent);

// Caps every opacity, seen through the 3D filter, at 0.01 and zeroes the opacity moments.
void reset_opacity(GaussianModel& model, GaussianOptimizer& optimizer);

}  // namespace iesrgs::gs
