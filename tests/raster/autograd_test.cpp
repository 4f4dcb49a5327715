#include "raster/autograd.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "core/error.hpp"
#include "gs/model.hpp"
#include "gs/random_model.hpp"
#include "raster_test_scene.hpp"
#include "support/cuda_device.hpp"

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
                    tensor_of(s.sh_dc, {n, 1, 3}),
                    tensor_of(s.sh_rest, {n, 15, 3}),
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
  EXPECT_EQ(values(out.alpha), raw.alpha);
  EXPECT_EQ(values(out.depth), raw.depth);
  std::vector<float> dmeans(3 * n), dscales(3 * n), dquats(4 * n), dlogits(n), dsh_dc(3 * n),
      dsh_rest(45 * n), dview(2 * n), dview_abs(2 * n);
  const std::vector<float> vwi = values(wi), vwa = values(wa), vwd = values(wd);
  rasterize_backward(
      s.params(), raw.frame, PixelGrads<float>{vwi.data(), vwa.data(), vwd.data()},
      GaussianGrads<float>{dmeans.data(), dscales.data(), dquats.data(), dlogits.data(),
                           dsh_dc.data(), dsh_rest.data(), dview.data(), dview_abs.data()});
  EXPECT_EQ(values(g.means.grad()), dmeans);
  EXPECT_EQ(values(g.log_scales.grad()), dscales);
  EXPECT_EQ(values(g.quats.grad()), dquats);
  EXPECT_EQ(values(g.opacity_logits.grad()), dlogits);
  EXPECT_EQ(values(g.sh_dc.grad()), dsh_dc);
  EXPECT_EQ(values(g.sh_rest.grad()), dsh_rest);
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
                    tensor_of(s.sh_dc, {n, 1, 3}),
                    tensor_of(s.sh_rest, {n, 15, 3}),
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

// The CUDA kernels behind render(): the same images and gradients as the CPU ones. Alphas within
// rounding of the 1/255 cut-off may flip at a few pixels (one splat's contribution).
TEST(RasterAutograd, CudaMatchesCpu) {
  IESRGS_SKIP_WITHOUT_CUDA();
  const Camera cam = posed_test_camera(120, 96);
  const Scene<float> s = random_scene(cam, 3000, 3, 29).cast<float>();
  const int64_t n = s.count();
  const GaussianTensors cpu{tensor_of(s.means, {n, 3}),    tensor_of(s.log_scales, {n, 3}),
                            tensor_of(s.quats, {n, 4}),    tensor_of(s.opacity_logits, {n}),
                            tensor_of(s.sh_dc, {n, 1, 3}), tensor_of(s.sh_rest, {n, 15, 3}),
                            torch::tensor(s.filter_std),   s.sh_degree};
  GaussianTensors gpu = cpu;
  for (torch::Tensor* t : {&gpu.means, &gpu.log_scales, &gpu.quats, &gpu.opacity_logits, &gpu.sh_dc,
                           &gpu.sh_rest, &gpu.filter_std})
    *t = testing::on_cuda(*t);
  const auto probes_on = [&](torch::Device device) {
    const auto options = torch::TensorOptions().device(device).requires_grad(true);
    return ViewspaceProbes{torch::zeros({n, 2}, options), torch::zeros({n, 2}, options)};
  };
  const ViewspaceProbes cpu_probes = probes_on(torch::kCPU), gpu_probes = probes_on(torch::kCUDA);
  torch::manual_seed(5);
  const torch::Tensor wi = torch::rand({3, cam.intrinsics.height, cam.intrinsics.width});
  const torch::Tensor wa = torch::rand({cam.intrinsics.height, cam.intrinsics.width});
  const auto render_and_backward = [&](const GaussianTensors& g, const ViewspaceProbes& probes) {
    const RenderOutput out = render(g, raster_camera<float>(cam), {0.3f, 0.6f, 0.9f}, probes);
    const torch::Device device = out.image.device();
    ((out.image * wi.to(device)).sum() + (out.alpha * wa.to(device)).sum() + 0.1 * out.depth.sum())
        .backward();
    return out;
  };
  const RenderOutput expected = render_and_backward(cpu, cpu_probes);
  const RenderOutput actual = render_and_backward(gpu, gpu_probes);
  ASSERT_TRUE(actual.image.is_cuda());
  EXPECT_TRUE(torch::equal(actual.radii.cpu(), expected.radii));
  for (const auto& [a, b] :
       {std::pair{actual.image, expected.image}, std::pair{actual.alpha, expected.alpha}}) {
    const torch::Tensor difference = (a.cpu() - b).abs();
    EXPECT_LT(difference.mean().item<double>(), 1e-5);
    EXPECT_LT(difference.max().item<double>(), 2e-3);
  }
  EXPECT_LT(testing::relative_difference(actual.depth, expected.depth), 1e-4);
  const std::pair<const char*, std::pair<torch::Tensor, torch::Tensor>> grads[] = {
      {"means", {gpu.means.grad(), cpu.means.grad()}},
      {"log_scales", {gpu.log_scales.grad(), cpu.log_scales.grad()}},
      {"quats", {gpu.quats.grad(), cpu.quats.grad()}},
      {"opacity_logits", {gpu.opacity_logits.grad(), cpu.opacity_logits.grad()}},
      {"sh_dc", {gpu.sh_dc.grad(), cpu.sh_dc.grad()}},
      {"sh_rest", {gpu.sh_rest.grad(), cpu.sh_rest.grad()}},
      {"viewspace", {gpu_probes.grad.grad(), cpu_probes.grad.grad()}},
      {"viewspace_abs", {gpu_probes.abs_grad.grad(), cpu_probes.abs_grad.grad()}}};
  for (const auto& [name, pair] : grads)
    EXPECT_LT(testing::relative_difference(pair.first, pair.second), 1e-3) << name;
}

TEST(RasterAutograd, RejectsWrongShapes) {
  const Camera cam = test_camera(16, 16);
  GaussianTensors g{
      torch::zeros({4, 3}),    torch::zeros({4, 3}),    torch::zeros({4, 4}), torch::zeros({4}),
      torch::zeros({4, 1, 3}), torch::zeros({4, 8, 3}), torch::Tensor(),      0};
  EXPECT_THROW(render(g, raster_camera<float>(cam), {0, 0, 0}), Error);
  g.sh_rest = torch::zeros({4, 15, 3}, torch::kFloat64);
  EXPECT_THROW(render(g, raster_camera<float>(cam), {0, 0, 0}), Error);
  // Tensors on a device this build has no rasterizer for.
  for (torch::Tensor* t :
       {&g.means, &g.log_scales, &g.quats, &g.opacity_logits, &g.sh_dc, &g.sh_rest})
    *t = torch::zeros(t->sizes(), torch::Device(torch::kMeta));
  try {
    render(g, raster_camera<float>(cam), {0, 0, 0});
    ADD_FAILURE() << "rendered tensors on the meta device";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "render: this build has no rasterizer for tensors on meta");
  }
}

TEST(RenderTensors, AreTheModelsParameters) {
  gs::GaussianModel m = gs::random_model(3);
  m.filter_3d = torch::rand({3});
  m.active_sh_degree = 2;
  const GaussianTensors t = render_tensors(m);
  for (int p = 0; p < gs::kParamCount; ++p) {
    const torch::Tensor& given = *std::array{&t.means,          &t.sh_dc,      &t.sh_rest,
                                             &t.opacity_logits, &t.log_scales, &t.quats}[size_t(p)];
    EXPECT_TRUE(given.is_same(m.param(gs::Param(p)))) << p;
  }
  EXPECT_TRUE(t.filter_std.is_same(m.filter_3d));
  EXPECT_EQ(t.sh_degree, 2);
}

}  // namespace
}  // namespace iesrgs::raster::testkit
