#include "gs/model.hpp"

#include <cmath>
#include <random>

#include "core/error.hpp"
#include "core/math.hpp"
#include "gs/filter3d.hpp"
#include "gs/neighbors.hpp"
#include "gs/sh.hpp"

namespace iesrgs::gs {

namespace {

constexpr int kRestCoefficients = kShCoefficients - 1;

torch::Tensor tensor_of(const std::vector<float>& values, c10::IntArrayRef shape) {
  return torch::from_blob(const_cast<float*>(values.data()), shape, torch::kFloat32).clone();
}

std::vector<float> values_of(const torch::Tensor& t) {
  const torch::Tensor c = t.detach().to(torch::kCPU).contiguous();
  return std::vector<float>(c.data_ptr<float>(), c.data_ptr<float>() + c.numel());
}

GaussianModel model_from_positions_and_dc(const std::vector<float>& positions,
                                          const std::vector<float>& sh_dc) {
  const int64_t n = int64_t(positions.size() / 3);
  const std::vector<float> dist2 = mean_knn_squared_distance(positions.data(), int(n));
  const torch::Tensor scale_log =
      torch::log(torch::sqrt(torch::clamp_min(tensor_of(dist2, {n}), 1e-7)));
  const float opacity = 0.1f;
  GaussianModel model;
  model.set_params({tensor_of(positions, {n, 3}), tensor_of(sh_dc, {n, 1, 3}),
                    torch::zeros({n, kRestCoefficients, 3}), torch::full({n}, logit(opacity)),
                    scale_log.unsqueeze(1).repeat({1, 3}),
                    torch::tensor({1.f, 0.f, 0.f, 0.f}).repeat({n, 1})});
  return model;
}

// Copies a (N, K - 1, 3) rest block into the first K - 1 rows of a zeroed (N, 15, 3) one.
torch::Tensor padded_rest(const SplatCloud& cloud) {
  const int64_t n = int64_t(cloud.size());
  const int64_t rest = sh_count(cloud.sh_degree) - 1;
  torch::Tensor out = torch::zeros({n, kRestCoefficients, 3});
  if (rest > 0) out.narrow(1, 0, rest).copy_(tensor_of(cloud.sh_rest, {n, rest, 3}));
  return out;
}

void check_cloud(const SplatCloud& cloud) {
  const size_t n = cloud.size();
  const bool consistent = cloud.sh_degree >= 0 && cloud.sh_degree <= kMaxShDegree &&
                          cloud.positions.size() == 3 * n && cloud.sh_dc.size() == 3 * n &&
                          cloud.sh_rest.size() == size_t(sh_count(cloud.sh_degree) - 1) * 3 * n &&
                          cloud.opacity.size() == n && cloud.log_scales.size() == 3 * n &&
                          cloud.rotations.size() == 4 * n &&
                          (cloud.filter_3d.empty() || cloud.filter_3d.size() == n);
  if (!consistent) fail("splat cloud: array sizes disagree with {} Gaussians", n);
}

}  // namespace

const char* param_name(Param p) {
  static const char* const kNames[kParamCount] = {"means",          "sh_dc",      "sh_rest",
                                                  "opacity_logits", "log_scales", "quats"};
  return kNames[int(p)];
}

torch::Tensor& GaussianModel::param(Param p) {
  return const_cast<torch::Tensor&>(static_cast<const GaussianModel&>(*this).param(p));
}

const torch::Tensor& GaussianModel::param(Param p) const {
  switch (p) {
    case Param::Means:
      return means;
    case Param::ShDc:
      return sh_dc;
    case Param::ShRest:
      return sh_rest;
    case Param::OpacityLogits:
      return opacity_logits;
    case Param::LogScales:
      return log_scales;
    case Param::Quats:
      return quats;
  }
  fail("unknown Gaussian parameter {}", int(p));
}

GaussianModel GaussianModel::clone() const {
  return to(means.device());
}

GaussianModel GaussianModel::to(torch::Device device) const {
  GaussianModel copy = *this;
  // One copy each, also on the same device, so that the two models share nothing.
  const auto copied = [device](const torch::Tensor& t) {
    return t.detach().to(t.options().device(device), /*non_blocking=*/false, /*copy=*/true);
  };
  for (int p = 0; p < kParamCount; ++p)
    copy.param(Param(p)) = copied(param(Param(p))).contiguous().requires_grad_(true);
  if (filter_3d.defined()) copy.filter_3d = copied(filter_3d);
  return copy;
}

void GaussianModel::set_param(Param p, const torch::Tensor& value) {
  param(p) = value.detach().clone().contiguous().requires_grad_(true);
}

void GaussianModel::set_params(const std::array<torch::Tensor, kParamCount>& values) {
  for (int p = 0; p < kParamCount; ++p) set_param(Param(p), values[p]);
}

GaussianModel model_from_points(const std::vector<float>& positions,
                                const std::vector<float>& colors) {
  if (positions.size() % 3 != 0 || colors.size() != positions.size())
    fail("initial points: {} coordinates and {} color values", positions.size(), colors.size());
  std::vector<float> dc(colors.size());
  for (size_t i = 0; i < colors.size(); ++i) dc[i] = (colors[i] - 0.5f) / float(kShC0);
  return model_from_positions_and_dc(positions, dc);
}

GaussianModel model_from_point_cloud(const PointCloud& cloud) {
  if (cloud.colors.size() != cloud.positions.size())
    fail("SfM points: {} positions but {} colors", cloud.positions.size(), cloud.colors.size());
  std::vector<float> positions, colors;
  positions.reserve(3 * cloud.positions.size());
  colors.reserve(3 * cloud.positions.size());
  for (size_t i = 0; i < cloud.positions.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      positions.push_back(float(cloud.positions[i][a]));
      colors.push_back(cloud.colors[i][a] / 255.f);
    }
  return model_from_points(positions, colors);
}

GaussianModel model_from_random_box(int count, float half_extent, uint64_t seed,
                                    const Vec3& center) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  std::vector<float> positions(3 * size_t(count)), dc(3 * size_t(count));
  for (size_t i = 0; i < positions.size(); ++i)
    positions[i] = float(center[int(i % 3)]) + (2 * unit(rng) - 1) * half_extent;
  for (float& c : dc) c = unit(rng) / 255.f;
  return model_from_positions_and_dc(positions, dc);
}

void update_filter_3d(GaussianModel& model, const std::vector<Camera>& cameras) {
  // On the CPU wherever the model is: it runs once per densification step or filter update.
  const std::vector<float> std_dev =
      filter3d_std(values_of(model.means).data(), int(model.size()), cameras);
  model.filter_3d = tensor_of(std_dev, {model.size()}).to(model.means.device());
}

SplatCloud to_splat_cloud(const GaussianModel& model) {
  SplatCloud cloud;
  cloud.sh_degree = kMaxShDegree;
  cloud.positions = values_of(model.means);
  cloud.sh_dc = values_of(model.sh_dc);
  cloud.sh_rest = values_of(model.sh_rest);
  cloud.opacity = values_of(model.opacity_logits);
  cloud.log_scales = values_of(model.log_scales);
  cloud.rotations = values_of(model.quats);
  if (model.filter_3d.defined()) cloud.filter_3d = values_of(model.filter_3d);
  cloud.antialiased = model.antialiased;
  return cloud;
}

GaussianModel model_from_splat_cloud(const SplatCloud& cloud) {
  check_cloud(cloud);
  const int64_t n = int64_t(cloud.size());
  GaussianModel model;
  model.set_params({tensor_of(cloud.positions, {n, 3}), tensor_of(cloud.sh_dc, {n, 1, 3}),
                    padded_rest(cloud), tensor_of(cloud.opacity, {n}),
                    tensor_of(cloud.log_scales, {n, 3}), tensor_of(cloud.rotations, {n, 4})});
  if (cloud.has_filter_3d()) model.filter_3d = tensor_of(cloud.filter_3d, {n});
  model.active_sh_degree = cloud.sh_degree;
  model.antialiased = cloud.antialiased;
  return model;
}

}  // namespace iesrgs::gs
