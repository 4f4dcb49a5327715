#include "raster/autograd.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "core/error.hpp"
#include "raster_test_scene.hpp"

namespace iesrgs::raster::testkit {
namespace {

torch::Tensor tensor_of(const std::vector<float>& v, std::vector<int64_t> shape) {
  return torch::tensor(v).reshape(shape).set_requires_grad(true);
}

std::vector<float> values(const torch::Tensor& t) {
  const torch::Tensor c = t.contiguous();
  return std::vector<float>(c.data_ptr<float>(), c.data_ptr<float>() + c.numel());
}

// The 2D filter choice travels through autograd's saved state to the backward pass.
void expect_gradients_match_the_raw_backward(bool antialiased) {
  const Camera cam = posed_test_camera(48, 40);
  Scene<float> s = random_scene(cam, 40, 3, 17).cast<float>();
  s.antialiased = antialiased;
  const int64_t n = s.count();
  const float bg[3] = {0.1f, 0.2f, 0.3f};
  GaussianTensors g{tensor_of(s.means, {n, 3}),
                    tensor_of(s.log_scales, {n, 3}),
                    tensor_of(s.quats, {n, 4}),
                    tensor_of(s.opacity_logits, {n}),
                    tensor_of(s.sh, {n, 16, 3}),
                    torch::tensor(s.filter_std),
                    s.sh_degree,
                    antialiased};
  ViewspaceProbes probes{torch::zeros({n, 2}).set_requires_grad(true),
                         torch::zeros({n, 2}).set_requires_grad(true)};
  const RenderOutput out = render(g, raster_camera<float>(cam), {bg[0], bg[1], bg[2]}, probes);

  // A loss that reaches every output: weighted image, alpha and depth.
  torch::manual_seed(3);
  const torch::Tensor wi = torch::rand_like(out.image), wa = torch::rand_like(out.alpha);
  const torch::Tensor wd = 0.1 * torch::rand_like(out.depth);
  ((out.image * wi).sum() + (out.alpha * wa).sum() + (out.depth * wd).sum()).backward();

  KernelRender<float> raw = kernel_render(s, cam, bg);
  EXPECT_EQ(values(out.image), raw.image);
  EXPECT_EQ(values(out.depth), raw.depth);
  std::vector<float> dmeans(3 * n), dscales(3 * n), dquats(4 * n), dlogits(n), dsh(48 * n),
      dview(2 * n), dview_abs(2 * n);
  const std::vector<float> vwi = values(wi), vwa = values(wa), vwd = values(wd);
  rasterize_backward(
      s.params(), raw.frame, PixelGrads<float>{vwi.data(), vwa.data(), vwd.data()},
      GaussianGrads<float>{dmeans.data(), dscales.data(), dquats.data(), dlogits.data(), dsh.data(),
                           dview.data(), dview_abs.data()});
  EXPECT_EQ(values(g.means.grad()), dmeans);
  EXPECT_EQ(values(g.log_scales.grad()), dscales);
  EXPECT_EQ(values(g.quats.grad()), dquats);
  EXPECT_EQ(values(g.opacity_logits.grad()), dlogits);
  EXPECT_EQ(values(g.sh.grad()), dsh);
  EXPECT_EQ(values(probes.grad.grad()), dview);
  EXPECT_EQ(values(probes.abs_grad.grad()), dview_abs);
  EXPECT_GT(torch::abs(g.means.grad()).sum().item<float>(), 0.f);
}

TEST(RasterAutograd, GradientsMatchTheRawBackward) {
  expect_gradients_match_the_raw_backward(true);
}

TEST(RasterAutograd, ClassicGradientsMatchTheRawBackward) {
  expect_gradients_match_the_raw_backward(false);
}

TEST(RasterAutograd, FilterAndProbesAreOptional) {
  const Camera cam = posed_test_camera(32, 24);
  const Scene<float> s = random_scene(cam, 20, 1, 5).cast<float>();
  const int64_t n = s.count();
  GaussianTensors g{tensor_of(s.means, {n, 3}),
                    tensor_of(s.log_scales, {n, 3}),
                    tensor_of(s.quats, {n, 4}),
                    tensor_of(s.opacity_logits, {n}),
                    tensor_of(s.sh, {n, 16, 3}),
                    torch::Tensor(),
                    s.sh_degree};
  const RenderOutput plain = render(g, raster_camera<float>(cam), {1, 1, 1});
  plain.image.sum().backward();
  const torch::Tensor grad_without_filter = g.means.grad().clone();
  EXPECT_GT(grad_without_filter.abs().sum().item<float>(), 0.f);

  // A zero filter renders exactly what no filter renders.
  g.means.grad().zero_();
  g.filter_std = torch::zeros({n});
  const RenderOutput zero_filter = render(g, raster_camera<float>(cam), {1, 1, 1});
  zero_filter.image.sum().backward();
  EXPECT_TRUE(torch::equal(zero_filter.image, plain.image));
  EXPECT_TRUE(torch::equal(g.means.grad(), grad_without_filter));
}

TEST(RasterAutograd, RejectsWrongShapes) {
  const Camera cam = test_camera(16, 16);
  GaussianTensors g{torch::zeros({4, 3}),
                    torch::zeros({4, 3}),
                    torch::zeros({4, 4}),
                    torch::zeros({4}),
                    torch::zeros({4, 9, 3}),
                    torch::Tensor(),
                    0};
  EXPECT_THROW(render(g, raster_camera<float>(cam), {0, 0, 0}), Error);
  g.sh = torch::zeros({4, 16, 3}, torch::kFloat64);
  EXPECT_THROW(render(g, raster_camera<float>(cam), {0, 0, 0}), Error);
}

}  // namespace
}  // namespace iesrgs::raster::testkit
