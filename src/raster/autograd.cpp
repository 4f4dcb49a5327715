#include "raster/autograd.hpp"

#include <torch/autograd.h>

#include <memory>
#include <mutex>
#include <vector>

#include "core/error.hpp"
#include "gs/model.hpp"
#include "gs/sh.hpp"
#include "raster/frame.hpp"
#include "raster/rasterizer.hpp"
#ifdef IESRGS_WITH_CUDA
#include "raster/cuda/rasterizer.hpp"
#endif

namespace iesrgs::raster {

namespace {

using torch::Tensor;
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// Frames whose autograd graph is gone: their buffers, grown to the scene, serve the next frames
// instead of being allocated, zeroed and freed for each render (host vectors for the CPU
// rasterizer, device buffers for the CUDA one).
template <typename Held>
class Pool {
 public:
  std::unique_ptr<Held> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty()) return std::make_unique<Held>();
    std::unique_ptr<Held> held = std::move(free_.back());
    free_.pop_back();
    return held;
  }
  void give_back(std::unique_ptr<Held> held) {
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(held));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<Held>> free_;
};

template <typename Held>
Pool<Held>& pool() {
  static Pool<Held>* pool = new Pool<Held>;  // never destroyed: outlives the CUDA context
  return *pool;
}

// Keeps the forward pass's frame alive until backward, inside the autograd context: the CPU
// rasterizer's frame, or the CUDA rasterizer that holds the frame's device buffers.
struct FrameHolder : torch::CustomClassHolder {
  std::unique_ptr<RasterFrame<float>> frame;
#ifdef IESRGS_WITH_CUDA
  std::unique_ptr<cuda::Rasterizer> device;
#endif
  ~FrameHolder() override {
    if (frame) pool<RasterFrame<float>>().give_back(std::move(frame));
#ifdef IESRGS_WITH_CUDA
    if (device) pool<cuda::Rasterizer>().give_back(std::move(device));
#endif
  }
};

void check_tensor(const Tensor& t, const char* name, std::initializer_list<int64_t> shape,
                  const torch::Device& device) {
  if (!t.defined()) fail("render: {} is missing", name);
  if (t.scalar_type() != torch::kFloat32) fail("render: {} must be a float32 tensor", name);
  if (t.device() != device)
    fail("render: {} is on {}, the Gaussians' means on {}", name, c10::str(t.device()),
         c10::str(device));
  if (t.sizes() != c10::IntArrayRef(shape))
    fail("render: {} has shape {}, expected {}", name, c10::str(t.sizes()),
         c10::str(c10::IntArrayRef(shape)));
}

void check_inputs(const GaussianTensors& g, const ViewspaceProbes& probes) {
  if (!g.means.defined()) fail("render: means is missing");
  const torch::Device device = g.means.device();
#ifdef IESRGS_WITH_CUDA
  const bool supported = device.is_cpu() || device.is_cuda();
#else
  const bool supported = device.is_cpu();
#endif
  if (!supported) fail("render: this build has no rasterizer for tensors on {}", c10::str(device));
  const int64_t n = g.means.size(0);
  check_tensor(g.means, "means", {n, 3}, device);
  check_tensor(g.log_scales, "log_scales", {n, 3}, device);
  check_tensor(g.quats, "quats", {n, 4}, device);
  check_tensor(g.opacity_logits, "opacity_logits", {n}, device);
  check_tensor(g.sh_dc, "sh_dc", {n, 1, 3}, device);
  check_tensor(g.sh_rest, "sh_rest", {n, gs::kShCoefficients - 1, 3}, device);
  if (g.filter_std.defined()) check_tensor(g.filter_std, "filter_std", {n}, device);
  if (probes.grad.defined()) check_tensor(probes.grad, "viewspace probe", {n, 2}, device);
  if (probes.abs_grad.defined())
    check_tensor(probes.abs_grad, "viewspace abs probe", {n, 2}, device);
}

GaussianParams<float> params_of_tensors(const Tensor& means, const Tensor& log_scales,
                                        const Tensor& quats, const Tensor& logits,
                                        const Tensor& sh_dc, const Tensor& sh_rest,
                                        const Tensor& filter_std, int sh_degree, bool antialiased) {
  GaussianParams<float> g;
  g.count = int(means.size(0));
  g.sh_degree = sh_degree;
  g.antialiased = antialiased;
  g.means = means.data_ptr<float>();
  g.log_scales = log_scales.data_ptr<float>();
  g.quats = quats.data_ptr<float>();
  g.opacity_logits = logits.data_ptr<float>();
  g.sh_dc = sh_dc.data_ptr<float>();
  g.sh_rest = sh_rest.data_ptr<float>();
  g.filter_std = filter_std.defined() ? filter_std.data_ptr<float>() : nullptr;
  return g;
}

float* data_or_null(const Tensor& t) {
  return t.defined() ? t.data_ptr<float>() : nullptr;
}

class RasterizeFunction : public torch::autograd::Function<RasterizeFunction> {
 public:
  // Probes are inputs only so that autograd routes the screen-space gradients to them. Optional
  // inputs arrive as empty placeholders (autograd cannot take undefined tensors) with a flag.
  static variable_list forward(AutogradContext* ctx, Tensor means, Tensor log_scales, Tensor quats,
                               Tensor logits, Tensor sh_dc, Tensor sh_rest, Tensor filter_std,
                               Tensor /*probe*/, Tensor /*abs_probe*/, RasterCamera<float> camera,
                               std::array<float, 3> background, int64_t sh_degree, bool antialiased,
                               std::array<bool, 3> present) {
    means = means.contiguous();
    log_scales = log_scales.contiguous();
    quats = quats.contiguous();
    logits = logits.contiguous();
    sh_dc = sh_dc.contiguous();
    sh_rest = sh_rest.contiguous();
    filter_std = present[0] ? filter_std.contiguous() : Tensor();
    const GaussianParams<float> g = params_of_tensors(
        means, log_scales, quats, logits, sh_dc, sh_rest, filter_std, int(sh_degree), antialiased);
    auto holder = c10::make_intrusive<FrameHolder>();
    const auto f32 = means.options();
    Tensor image = torch::empty({3, camera.height, camera.width}, f32);
    Tensor alpha = torch::empty({camera.height, camera.width}, f32);
    Tensor depth = torch::empty({camera.height, camera.width}, f32);
    Tensor radii = torch::empty({g.count}, f32.dtype(torch::kInt32));
    const RenderTargets<float> targets{image.data_ptr<float>(), alpha.data_ptr<float>(),
                                       depth.data_ptr<float>(), radii.data_ptr<int32_t>()};
#ifdef IESRGS_WITH_CUDA
    if (means.is_cuda()) {
      holder->device = pool<cuda::Rasterizer>().take();
      holder->device->forward(g, camera, background.data(), targets);
    } else
#endif
    {
      holder->frame = pool<RasterFrame<float>>().take();
      rasterize_forward(g, camera, background.data(), *holder->frame, targets);
    }
    ctx->save_for_backward({means, log_scales, quats, logits, sh_dc, sh_rest, filter_std});
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
    const GaussianParams<float> g = params_of_tensors(
        means, saved[1], saved[2], saved[3], saved[4], saved[5], saved[6],
        int(ctx->saved_data["sh_degree"].toInt()), ctx->saved_data["antialiased"].toBool());
    auto holder =
        c10::static_intrusive_pointer_cast<FrameHolder>(ctx->saved_data["frame"].toCapsule());
    Tensor dmeans = torch::empty_like(means), dlog_scales = torch::empty_like(saved[1]);
    Tensor dquats = torch::empty_like(saved[2]), dlogits = torch::empty_like(saved[3]);
    Tensor dsh_dc = torch::empty_like(saved[4]), dsh_rest = torch::empty_like(saved[5]);
    Tensor dprobe =
        ctx->saved_data["probe"].toBool() ? torch::empty({g.count, 2}, means.options()) : Tensor();
    Tensor dabs_probe = ctx->saved_data["abs_probe"].toBool()
                            ? torch::empty({g.count, 2}, means.options())
                            : Tensor();
    std::array<Tensor, 3> pixel;
    for (int i = 0; i < 3; ++i)
      if (grad_outputs[i].defined()) pixel[i] = grad_outputs[i].contiguous();
    const PixelGrads<float> pixel_grads{data_or_null(pixel[0]), data_or_null(pixel[1]),
                                        data_or_null(pixel[2])};
    const GaussianGrads<float> grads{dmeans.data_ptr<float>(), dlog_scales.data_ptr<float>(),
                                     dquats.data_ptr<float>(), dlogits.data_ptr<float>(),
                                     dsh_dc.data_ptr<float>(), dsh_rest.data_ptr<float>(),
                                     data_or_null(dprobe),     data_or_null(dabs_probe)};
#ifdef IESRGS_WITH_CUDA
    if (holder->device)
      holder->device->backward(g, pixel_grads, grads);
    else
#endif
      rasterize_backward(g, *holder->frame, pixel_grads, grads);
    return {dmeans, dlog_scales, dquats,   dlogits,  dsh_dc,   dsh_rest, Tensor(),
            dprobe, dabs_probe,  Tensor(), Tensor(), Tensor(), Tensor(), Tensor()};
  }
};

}  // namespace

GaussianTensors render_tensors(const gs::GaussianModel& model) {
  return {model.means,      model.log_scales, model.quats,     model.opacity_logits,
          model.sh_dc,      model.sh_rest,    model.filter_3d, model.active_sh_degree,
          model.antialiased};
}

RenderOutput render(const GaussianTensors& gaussians, const RasterCamera<float>& camera,
                    const std::array<float, 3>& background, const ViewspaceProbes& probes) {
  check_inputs(gaussians, probes);
  const auto or_placeholder = [&](const Tensor& t) {
    return t.defined() ? t : torch::empty({0}, gaussians.means.options());
  };
  const variable_list out = RasterizeFunction::apply(
      gaussians.means, gaussians.log_scales, gaussians.quats, gaussians.opacity_logits,
      gaussians.sh_dc, gaussians.sh_rest, or_placeholder(gaussians.filter_std),
      or_placeholder(probes.grad), or_placeholder(probes.abs_grad), camera, background,
      int64_t(gaussians.sh_degree), gaussians.antialiased,
      std::array<bool, 3>{gaussians.filter_std.defined(), probes.grad.defined(),
                          probes.abs_grad.defined()});
  return {out[0], out[1], out[2], out[3]};
}

GaussianParams<float> kernel_params(const GaussianTensors& gaussians) {
  check_inputs(gaussians, {});
  for (const Tensor* t :
       {&gaussians.means, &gaussians.log_scales, &gaussians.quats, &gaussians.opacity_logits,
        &gaussians.sh_dc, &gaussians.sh_rest, &gaussians.filter_std})
    if (t->defined() && !t->is_contiguous()) fail("kernel_params: a tensor is not contiguous");
  return params_of_tensors(gaussians.means, gaussians.log_scales, gaussians.quats,
                           gaussians.opacity_logits, gaussians.sh_dc, gaussians.sh_rest,
                           gaussians.filter_std, gaussians.sh_degree, gaussians.antialiased);
}

}  // namespace iesrgs::raster
