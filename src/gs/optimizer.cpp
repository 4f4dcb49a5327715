#include "gs/optimizer.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "gs/adam.hpp"
#ifdef IESRGS_WITH_CUDA
#include "gs/cuda/adam.hpp"
#endif

namespace iesrgs::gs {

namespace {

void adam_update(float* param, const float* grad, float* first, float* second, int64_t count,
                 float step_size, float bias2_sqrt) {
#pragma omp parallel for simd schedule(static)
  for (int64_t i = 0; i < count; ++i)
    adam_update_value(param[i], grad[i], first[i], second[i], step_size, bias2_sqrt);
}

#ifdef IESRGS_WITH_CUDA
void device_adam_update(float* param, const float* grad, float* first, float* second, int64_t count,
                        float step_size, float bias2_sqrt) {
  cuda::adam_update(param, grad, first, second, count, step_size, bias2_sqrt);
}
#else
void device_adam_update(float*, const float*, float*, float*, int64_t, float, float) {
  fail("optimizer step: this build has no CUDA kernels");
}
#endif

}  // namespace

double ExponentialLr::operator()(int64_t step) const {
  if (step < 0 || (initial == 0 && final == 0)) return 0;
  const double t = std::clamp(double(step) / double(max_steps), 0.0, 1.0);
  return std::exp(std::log(initial) * (1 - t) + std::log(final) * t);
}

GaussianOptimizer::GaussianOptimizer(const GaussianModel& model, const LearningRates& rates,
                                     double scene_extent)
    : rates_(rates),
      position_lr_{rates.position_initial * scene_extent, rates.position_final * scene_extent,
                   rates.position_max_steps} {
  for (int p = 0; p < kParamCount; ++p) {
    const torch::Tensor& t = model.param(Param(p));
    moments_[p] = {torch::zeros_like(t, torch::requires_grad(false)),
                   torch::zeros_like(t, torch::requires_grad(false))};
  }
}

double GaussianOptimizer::learning_rate(Param p) const {
  switch (p) {
    case Param::Means:
      return position_lr_(steps_ + 1);  // 3DGS counts iterations from 1
    case Param::ShDc:
      return rates_.sh_dc;
    case Param::ShRest:
      return rates_.sh_rest;
    case Param::OpacityLogits:
      return rates_.opacity;
    case Param::LogScales:
      return rates_.scaling;
    case Param::Quats:
      return rates_.rotation;
  }
  fail("unknown Gaussian parameter {}", int(p));
}

void GaussianOptimizer::step(GaussianModel& model) {
  const int64_t step = steps_ + 1;
  const double bias1 = 1 - std::pow(kAdamBeta1, double(step));
  const double bias2 = 1 - std::pow(kAdamBeta2, double(step));
  for (int p = 0; p < kParamCount; ++p) {
    torch::Tensor& param = model.param(Param(p));
    const torch::Tensor& grad = param.grad();
    if (!grad.defined()) fail("optimizer step: {} has no gradient", param_name(Param(p)));
    if (grad.sizes() != moments_[p].first.sizes())
      fail("optimizer step: {} has shape {} but its moments {}", param_name(Param(p)),
           c10::str(grad.sizes()), c10::str(moments_[p].first.sizes()));
    if (!param.is_contiguous())  // updated in place through its data pointer
      fail("optimizer step: {} is not contiguous", param_name(Param(p)));
    if (param.device() != moments_[p].first.device())
      fail("optimizer step: {} is on {}, its moments on {}", param_name(Param(p)),
           c10::str(param.device()), c10::str(moments_[p].first.device()));
    const torch::Tensor g = grad.contiguous();
    const auto update = param.is_cuda() ? device_adam_update : adam_update;
    update(param.data_ptr<float>(), g.data_ptr<float>(), moments_[p].first.data_ptr<float>(),
           moments_[p].second.data_ptr<float>(), param.numel(),
           float(learning_rate(Param(p)) / bias1), float(std::sqrt(bias2)));
  }
  steps_ = step;
}

void GaussianOptimizer::append_rows(int64_t count) {
  for (AdamMoments& m : moments_) {
    std::vector<int64_t> shape = m.first.sizes().vec();
    shape[0] = count;
    m.first = torch::cat({m.first, torch::zeros(shape, m.first.options())});
    m.second = torch::cat({m.second, torch::zeros(shape, m.second.options())});
  }
}

void GaussianOptimizer::keep_rows(const torch::Tensor& keep) {
  for (AdamMoments& m : moments_) {
    m.first = m.first.index({keep}).contiguous();
    m.second = m.second.index({keep}).contiguous();
  }
}

void GaussianOptimizer::to(torch::Device device) {
  for (AdamMoments& m : moments_) {
    m.first = m.first.to(device);
    m.second = m.second.to(device);
  }
}

void GaussianOptimizer::reset_moments(Param p) {
  moments_[int(p)].first.zero_();
  moments_[int(p)].second.zero_();
}

void GaussianOptimizer::save_state(torch::serialize::OutputArchive& archive) const {
  archive.write("adam/steps", torch::tensor(steps_, torch::kInt64));
  for (int p = 0; p < kParamCount; ++p) {
    archive.write(std::string("adam/first/") + param_name(Param(p)), moments_[p].first);
    archive.write(std::string("adam/second/") + param_name(Param(p)), moments_[p].second);
  }
}

void GaussianOptimizer::load_state(torch::serialize::InputArchive& archive,
                                   const GaussianModel& model) {
  torch::Tensor steps;
  archive.read("adam/steps", steps);
  std::array<AdamMoments, kParamCount> loaded;
  for (int p = 0; p < kParamCount; ++p) {
    archive.read(std::string("adam/first/") + param_name(Param(p)), loaded[p].first);
    archive.read(std::string("adam/second/") + param_name(Param(p)), loaded[p].second);
    const auto shape = model.param(Param(p)).sizes();
    if (loaded[p].first.sizes() != shape || loaded[p].second.sizes() != shape ||
        loaded[p].first.scalar_type() != torch::kFloat32 ||
        loaded[p].second.scalar_type() != torch::kFloat32)
      fail("optimizer state: {} moments do not match the model's shape {}", param_name(Param(p)),
           c10::str(shape));
  }
  if (steps.numel() != 1 || steps.scalar_type() != torch::kInt64 || steps.item<int64_t>() < 0)
    fail("optimizer state: invalid step count");
  steps_ = steps.item<int64_t>();
  moments_ = loaded;
}

}  // namespace iesrgs::gs
