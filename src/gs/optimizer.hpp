#pragma once
// Adam over the Gaussian parameters with 3DGS's per-group learning rates, as one fused pass per
// group over the raw float arrays. Its moments are plain tensors with one row per Gaussian so
// that densification can grow, shrink and reset them together with the model.
#include <torch/serialize/archive.h>
#include <torch/types.h>

#include <array>
#include <cstdint>

#include "gs/model.hpp"

namespace iesrgs::gs {

// 3DGS's get_expon_lr_func without the delay phase (unused by its defaults): log-linear from
// `initial` at step 0 to `final` at `max_steps`, constant after.
struct ExponentialLr {
  double initial = 0, final = 0;
  int64_t max_steps = 1;

  double operator()(int64_t step) const;
};

// 3DGS defaults; the position rates are multiplied by the scene extent.
struct LearningRates {
  double position_initial = 1.6e-4, position_final = 1.6e-6;
  int64_t position_max_steps = 30000;
  double sh_dc = 2.5e-3, sh_rest = 2.5e-3 / 20, opacity = 0.05, scaling = 5e-3, rotation = 1e-3;
};

struct AdamMoments {
  torch::Tensor first, second;  // exp_avg, exp_avg_sq, shaped as the parameter
};

class GaussianOptimizer {
 public:
  GaussianOptimizer(const GaussianModel& model, const LearningRates& rates, double scene_extent);

  // One Adam step of every group from the parameters' .grad() (which must all be defined), with
  // the position rate of the step about to be taken; does not zero the gradients.
  void step(GaussianModel& model);

  // Learning rate that group `p` uses at the next step.
  double learning_rate(Param p) const;
  int64_t steps_taken() const { return steps_; }
  const AdamMoments& moments(Param p) const { return moments_[int(p)]; }

  // Densification bookkeeping, as 3DGS's optimizer surgery: appended rows start with zero
  // moments, `keep` (bool (N)) drops rows, and a reset zeroes one group's moments.
  void append_rows(int64_t count);
  void keep_rows(const torch::Tensor& keep);
  void reset_moments(Param p);
  // Moves the moments to `device`, where the model's parameters are.
  void to(torch::Device device);

  // Exact state for resume. `load_state` throws Error when a moment's shape differs from its
  // parameter's in `model`.
  void save_state(torch::serialize::OutputArchive& archive) const;
  void load_state(torch::serialize::InputArchive& archive, const GaussianModel& model);

 private:
  LearningRates rates_;
  ExponentialLr position_lr_;
  int64_t steps_ = 0;
  std::array<AdamMoments, kParamCount> moments_;
};

}  // namespace iesrgs::gs
