#include "raster/autograd.hpp"

#include <torch/autograd.h>

#include "core/error.hpp"
#include "gs/sh.hpp"
#include "raster/frame.hpp"
#include "raster/rasterizer.hpp"

namespace iesrgs::raster {

namespace {

using torch::Tensor;
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// Keeps the forward pass's frame alive until backward, inside the autograd context.
struct FrameHolder : torch::CustomClassHolder {
  RasterFrame<float> frame;
};

void check_tensor(const Tensor& t, const char* name, std::initializer_list<int64_t> shape) {
  if (!t.defined()) fail("render: {} is missing", name);
  if (t.scalar_type() != torch::kFloat32 || !t.device().is_cpu())
    fail("render: {} must be a float32 CPU tensor", name);
  if (t.sizes() != c10::IntArrayRef(shape))
    fail("render: {} has shape {}, expected {}", name, c10::str(t.sizes()),
         c10::str(c10::IntArrayRef(shape)));
}

void check_inputs(const GaussianTensors& g, const ViewspaceProbes& probes) {
  const int64_t n = g.means.defined() ? g.means.size(0) : 0;
  check_tensor(g.means, "means", {n, 3});
  check_tensor(g.log_scales, "log_scales", {n, 3});
  check_tensor(g.quats, "quats", {n, 4});
  check_tensor(g.opacity_logits, "opacity_logits", {n});
  check_tensor(g.sh, "sh", {n, gs::kShCoefficients, 3});
  if (g.filter_std.defined()) check_tensor(g.filter_std, "filter_std", {n});
  if (probes.grad.defined()) check_tensor(probes.grad, "viewspace probe", {n, 2});
  if (probes.abs_grad.defined()) check_tensor(probes.abs_grad, "viewspace abs probe", {n, 2});
}

GaussianParams<float> params_of(const Tensor& means, const Tensor& log_scales, const Tensor& quats,
                                const Tensor& logits, const Tensor& sh, const Tensor& filter_std,
                                int sh_degree, bool antialiased) {
  GaussianParams<float> g;
  g.count = int(means.size(0));
  g.sh_degree = sh_degree;
  g.antialiased = antialiased;
  g.means = means.data_ptr<float>();
  g.log_scales = log_scales.data_ptr<float>();
  g.quats = quats.data_ptr<float>();
  g.opacity_logits = logits.data_ptr<float>();
  g.sh = sh.data_ptr<float>();
  g.filter_std = filter_std.defined() ? filter_std.data_ptr<float>() : nullptr;
  return g;
}

const float* data_or_null(const Tensor& t) {
  return t.defined() ? t.data_ptr<float>() : nullptr;
}

class RasterizeFunction : public torch::autograd::Function<RasterizeFunction> {
 public:
  // Probes are inputs only so that autograd routes the screen-space gradients to them. Optional
  // inputs arrive as empty placeholders (autograd cannot take undefined tensors) with a flag.
  static variable_list forward(AutogradContext* ctx, Tensor means, Tensor log_scales, Tensor quats,
                               Tensor logits, Tensor sh, Tensor filter_std, Tensor /*probe*/,
                               Tensor /*abs_probe*/, RasterCamera<float> camera,
                               std::array<float, 3> background, int64_t sh_degree, bool antialiased,
                               std::array<bool, 3> present) {
    means = means.contiguous();
    log_scales = log_scales.contiguous();
    quats = quats.contiguous();
    logits = logits.contiguous();
    sh = sh.contiguous();
    filter_std = present[0] ? filter_std.contiguous() : Tensor();
    const GaussianParams<float> g =
        params_of(means, log_scales, quats, logits, sh, filter_std, int(sh_degree), antialiased);
    auto holder = c10::make_intrusive<FrameHolder>();
    const auto f32 = torch::TensorOptions().dtype(torch::kFloat32);
    Tensor image = torch::empty({3, camera.height, camera.width}, f32);
    Tensor alpha = torch::empty({camera.height, camera.width}, f32);
    Tensor depth = torch::empty({camera.height, camera.width}, f32);
    Tensor radii = torch::empty({g.count}, f32.dtype(torch::kInt32));
    rasterize_forward(g, camera, background.data(), holder->frame,
                      RenderTargets<float>{image.data_ptr<float>(), alpha.data_ptr<float>(),
                                           depth.data_ptr<float>(), radii.data_ptr<int32_t>()});
    ctx->save_for_backward({means, log_scales, quats, logits, sh, filter_std});
    ctx->saved_data["frame"] = c10::IValue::make_capsule(holder);
    ctx->saved_data["sh_degree"] = sh_degree;
    ctx->saved_data["antialiased"] = antialiased;
    ctx->saved_data["probe"] = present[1];
    ctx->saved_data["abs_probe"] = present[2];
    ctx->mark_non_differentiable({radii});
    return {image, alpha, depth, radii};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grad_outputs) {
    const variable_list saved = ctx->get_saved_variables();
    const Tensor& means = saved[0];
    const GaussianParams<float> g = params_of(means, saved[1], saved[2], saved[3], saved[4],
                                              saved[5], int(ctx->saved_data["sh_degree"].toInt()),
                                              ctx->saved_data["antialiased"].toBool());
    auto holder =
        c10::static_intrusive_pointer_cast<FrameHolder>(ctx->saved_data["frame"].toCapsule());
    Tensor dmeans = torch::empty_like(means), dlog_scales = torch::empty_like(saved[1]);
    Tensor dquats = torch::empty_like(saved[2]), dlogits = torch::empty_like(saved[3]);
    Tensor dsh = torch::empty_like(saved[4]);
    Tensor dprobe =
        ctx->saved_data["probe"].toBool() ? torch::empty({g.count, 2}, means.options()) : Tensor();
    Tensor dabs_probe = ctx->saved_data["abs_probe"].toBool()
                            ? torch::empty({g.count, 2}, means.options())
                            : Tensor();
    std::array<Tensor, 3> pixel;
    for (int i = 0; i < 3; ++i)
      if (grad_outputs[i].defined()) pixel[i] = grad_outputs[i].contiguous();
    rasterize_backward(
        g, holder->frame,
        PixelGrads<float>{data_or_null(pixel[0]), data_or_null(pixel[1]), data_or_null(pixel[2])},
        GaussianGrads<float>{dmeans.data_ptr<float>(), dlog_scales.data_ptr<float>(),
                             dquats.data_ptr<float>(), dlogits.data_ptr<float>(),
                             dsh.data_ptr<float>(),
                             dprobe.defined() ? dprobe.data_ptr<float>() : nullptr,
                             dabs_probe.defined() ? dabs_probe.data_ptr<float>() : nullptr});
    return {dmeans,     dlog_scales, dquats,   dlogits,  dsh,      Tensor(), dprobe,
            dabs_probe, Tensor(),    Tensor(), Tensor(), Tensor(), Tensor()};
  }
};

}  // namespace

RenderOutput render(const GaussianTensors& gaussians, const RasterCamera<float>& camera,
                    const std::array<float, 3>& background, const ViewspaceProbes& probes) {
  check_inputs(gaussians, probes);
  const auto or_placeholder = [](const Tensor& t) { return t.defined() ? t : torch::empty({0}); };
  const variable_list out = RasterizeFunction::apply(
      gaussians.means, gaussians.log_scales, gaussians.quats, gaussians.opacity_logits,
      gaussians.sh, or_placeholder(gaussians.filter_std), or_placeholder(probes.grad),
      or_placeholder(probes.abs_grad), camera, background, int64_t(gaussians.sh_degree),
      gaussians.antialiased,
      std::array<bool, 3>{gaussians.filter_std.defined(), probes.grad.defined(),
                          probes.abs_grad.defined()});
  return {out[0], out[1], out[2], out[3]};
}

}  // namespace iesrgs::raster
