#include "loss/autograd.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <type_traits>

#include <ATen/ATen.h>
#include <torch/csrc/autograd/custom_function.h>

#include "core/error.hpp"
#include "loss/depth_l1.hpp"
#include "loss/pearson.hpp"
#include "loss/ssim.hpp"
#include "loss/texture_fusion.hpp"
#ifdef IESRGS_WITH_CUDA
#include "loss/cuda/ssim.hpp"
#endif

namespace iesrgs::loss {

ImageShape chw_shape(const at::Tensor& image, const char* what) {
  constexpr int64_t kMaxSide = std::numeric_limits<int>::max();
  if (image.dim() != 3 || image.size(0) > kMaxSide || image.size(1) > kMaxSide ||
      image.size(2) > kMaxSide)
    fail("{}: image shape {} is not (C, H, W)", what, c10::str(image.sizes()));
  const ImageShape shape{int(image.size(2)), int(image.size(1)), int(image.size(0))};
  check_shape(shape, what);
  return shape;
}

namespace {

using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

// Calls body(T{}) with T the tensor's scalar type, float or double.
template <typename Body>
auto with_scalar_type(const at::Tensor& tensor, Body&& body) {
  return tensor.scalar_type() == at::kDouble ? body(double{}) : body(float{});
}

void check_loss_inputs(const char* what, const at::Tensor& value, const at::Tensor& target) {
  if (!value.defined() || !target.defined()) fail("{}: undefined tensor", what);
  if (value.device() != target.device())
    fail("{}: the target is on {}, the value on {}", what, c10::str(target.device()),
         c10::str(value.device()));
  if (value.scalar_type() != at::kFloat && value.scalar_type() != at::kDouble)
    fail("{}: dtype {} is not float32 or float64", what, c10::toString(value.scalar_type()));
  if (target.scalar_type() != value.scalar_type())
    fail("{}: target dtype {} differs from {}", what, c10::toString(target.scalar_type()),
         c10::toString(value.scalar_type()));
  if (target.sizes() != value.sizes())
    fail("{}: target shape {} differs from {}", what, c10::str(target.sizes()),
         c10::str(value.sizes()));
  if (target.requires_grad()) fail("{}: the target must not require grad", what);
}

#ifdef IESRGS_WITH_CUDA
// One SSIM workspace per thread, grown to the largest image and kept.
cuda::Ssim& device_ssim() {
  static thread_local cuda::Ssim* ssim = new cuda::Ssim;  // outlives the CUDA context
  return *ssim;
}
#endif

// SSIM's kernels: the CPU ones, and in a CUDA build the CUDA ones for float32 tensors on a GPU.
void require_ssim_kernel_for(const at::Tensor& x, const char* what) {
  if (x.device().is_cpu()) return;
#ifdef IESRGS_WITH_CUDA
  if (x.is_cuda() && x.scalar_type() == at::kFloat) return;
#endif
  fail("{}: this build has no kernel for {} tensors on {}", what, c10::toString(x.scalar_type()),
       c10::str(x.device()));
}

class SsimFunction : public torch::autograd::Function<SsimFunction> {
 public:
  static variable_list forward(AutogradContext* ctx, const at::Tensor& x_in,
                               const at::Tensor& y_in) {
    const at::Tensor x = x_in.contiguous(), y = y_in.contiguous();
    const ImageShape shape = chw_shape(x, "ssim");
    at::Tensor map = at::empty({shape.height, shape.width}, x.options());
    at::Tensor partials = at::empty({int64_t(ssim_partials_size(shape))}, x.options());
    const at::Tensor mean = with_scalar_type(x, [&](auto zero) {
      using T = decltype(zero);
#ifdef IESRGS_WITH_CUDA
      if constexpr (std::is_same_v<T, float>)
        if (x.is_cuda()) {  // the mean stays on the device: no wait for the GPU
          at::Tensor out = at::empty({}, x.options());
          device_ssim().forward(x.data_ptr<float>(), y.data_ptr<float>(), shape,
                                map.data_ptr<float>(), partials.data_ptr<float>(),
                                out.data_ptr<float>());
          return out;
        }
#endif
      return at::scalar_tensor(ssim<T>(x.data_ptr<T>(), y.data_ptr<T>(), shape, map.data_ptr<T>(),
                                       partials.data_ptr<T>()),
                               x.options());
    });
    ctx->save_for_backward({x, y, partials});
    return {mean, map};
  }

  // Upstream gradients arrive materialized (zeros for an unused output).
  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor &x = saved[0], &y = saved[1], &partials = saved[2];
    const ImageShape shape = chw_shape(x, "ssim");
    // d mean / d map[p] = 1 / pixels.
    const at::Tensor weight = (grads[1] + grads[0] / double(shape.pixels())).contiguous();
    at::Tensor grad_x = at::zeros_like(x);
    with_scalar_type(x, [&](auto zero) {
      using T = decltype(zero);
#ifdef IESRGS_WITH_CUDA
      if constexpr (std::is_same_v<T, float>)
        if (x.is_cuda())
          return device_ssim().backward(x.data_ptr<float>(), y.data_ptr<float>(), shape,
                                        partials.data_ptr<float>(), weight.data_ptr<float>(),
                                        grad_x.data_ptr<float>());
#endif
      ssim_backward<T>(x.data_ptr<T>(), y.data_ptr<T>(), shape, partials.data_ptr<T>(),
                       weight.data_ptr<T>(), grad_x.data_ptr<T>());
    });
    return {grad_x, at::Tensor()};
  }
};

class PearsonFunction : public torch::autograd::Function<PearsonFunction> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& a_in, const at::Tensor& b_in,
                            const at::Tensor& mask_in) {
    const at::Tensor a = a_in.contiguous(), b = b_in.contiguous();
    const at::Tensor mask = (mask_in != 0).to(at::kByte).contiguous();
    const double correlation = with_scalar_type(a, [&](auto zero) {
      using T = decltype(zero);
      return pearson_correlation<T>(a.data_ptr<T>(), b.data_ptr<T>(), mask.data_ptr<uint8_t>(),
                                    a.numel());
    });
    ctx->save_for_backward({a, b, mask});
    return at::scalar_tensor(correlation, a_in.options());
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor &a = saved[0], &b = saved[1], &mask = saved[2];
    at::Tensor grad_a = at::zeros_like(a);
    with_scalar_type(a, [&](auto zero) {
      using T = decltype(zero);
      pearson_correlation_backward<T>(a.data_ptr<T>(), b.data_ptr<T>(), mask.data_ptr<uint8_t>(),
                                      a.numel(), grads[0].item<double>(), grad_a.data_ptr<T>());
    });
    return {grad_a, at::Tensor(), at::Tensor()};
  }
};

class CoveredDepthL1Function : public torch::autograd::Function<CoveredDepthL1Function> {
 public:
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& depth_in,
                            const at::Tensor& alpha_in, const at::Tensor& reference_in) {
    const at::Tensor depth = depth_in.contiguous(), alpha = alpha_in.contiguous();
    const at::Tensor reference = reference_in.contiguous();
    const CoveredDepthL1 l1 = with_scalar_type(depth, [&](auto zero) {
      using T = decltype(zero);
      return covered_depth_l1<T>(depth.data_ptr<T>(), alpha.data_ptr<T>(), reference.data_ptr<T>(),
                                 depth.numel());
    });
    ctx->save_for_backward({depth, alpha, reference});
    ctx->saved_data["pixels"] = l1.pixels;
    return at::scalar_tensor(l1.mean, depth.options());
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const variable_list saved = ctx->get_saved_variables();
    const at::Tensor &depth = saved[0], &alpha = saved[1], &reference = saved[2];
    at::Tensor grad_depth = at::empty_like(depth), grad_alpha = at::empty_like(alpha);
    const int64_t pixels = std::max<int64_t>(ctx->saved_data["pixels"].toInt(), 1);
    with_scalar_type(depth, [&](auto zero) {
      using T = decltype(zero);
      // The upstream gradient over the pixel count, divided in T as autograd divides it.
      const T scale = grads[0].item<T>() / T(pixels);
      covered_depth_l1_backward<T>(depth.data_ptr<T>(), alpha.data_ptr<T>(),
                                   reference.data_ptr<T>(), depth.numel(), scale,
                                   grad_depth.data_ptr<T>(), grad_alpha.data_ptr<T>());
    });
    return {grad_depth, grad_alpha, at::Tensor()};
  }
};

class GuidedTextureFunction : public torch::autograd::Function<GuidedTextureFunction> {
 public:
  // An undefined reference travels as an empty tensor: autograd::Function takes defined ones.
  static at::Tensor forward(AutogradContext* ctx, const at::Tensor& render_in,
                            const at::Tensor& internal_in, const at::Tensor& external_in,
                            const at::Tensor& share_in, double dssim_weight) {
    const at::Tensor render = render_in.contiguous(), internal = internal_in.contiguous();
    const at::Tensor external = external_in.contiguous(), share = share_in.contiguous();
    const ImageShape shape = chw_shape(render, "guided texture loss");
    at::Tensor grad = at::zeros_like(render);
    const double loss = with_scalar_type(render, [&](auto zero) {
      using T = decltype(zero);
      const auto data = [](const at::Tensor& t) { return t.numel() ? t.data_ptr<T>() : nullptr; };
      return guided_texture_loss<T>(render.data_ptr<T>(), data(internal), data(external),
                                    share.data_ptr<T>(), shape, dssim_weight, grad.data_ptr<T>());
    });
    // The loss is linear in its upstream gradient, so the full gradient is computed once here.
    ctx->save_for_backward({grad});
    return at::scalar_tensor(loss, render.options());
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    at::Tensor grad = ctx->get_saved_variables()[0];
    // A training step's upstream gradient is 1: no product image to allocate and fill.
    if (grads[0].item<double>() != 1) grad = grad * grads[0];
    return {grad, at::Tensor(), at::Tensor(), at::Tensor(), at::Tensor()};
  }
};

}  // namespace

SsimTensors ssim_autograd(const at::Tensor& x, const at::Tensor& y) {
  check_loss_inputs("ssim", x, y);
  require_ssim_kernel_for(x, "ssim");
  const variable_list out = SsimFunction::apply(x, y);
  return {out[0], out[1]};
}

at::Tensor pearson_autograd(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  check_loss_inputs("pearson", a, b);
  if (mask.defined() && mask.sizes() != a.sizes())
    fail("pearson: mask must have shape {}, not {}", c10::str(a.sizes()), c10::str(mask.sizes()));
  if (mask.defined() && mask.device() != a.device())
    fail("pearson: the mask is on {}, the values on {}", c10::str(mask.device()),
         c10::str(a.device()));
  const at::Tensor selected =
      mask.defined() ? mask : at::ones(a.sizes(), a.options().dtype(at::kByte));
  if (!a.device().is_cpu())
    return pearson_from_ops(a, b, selected);  // the kernel reads host memory
  return PearsonFunction::apply(a, b, selected);
}

at::Tensor pearson_from_ops(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  // In double and centered, as the kernel sums, so that far depths keep their precision.
  const at::Tensor weight = (mask != 0).to(at::kDouble);
  const at::Tensor count = weight.sum();
  const auto centered = [&](const at::Tensor& t) {  // minus the selected mean; 0 off the mask
    const at::Tensor v = t.to(at::kDouble);
    return weight * (v - (weight * v).sum() / count.clamp_min(1));
  };
  const at::Tensor dx = centered(a), dy = centered(b);
  const at::Tensor xx = (dx * dx).sum(), yy = (dy * dy).sum();
  // An undefined correlation (fewer than two entries, or a constant side) is 0, as in the kernel;
  // the clamp keeps the unused branch's gradient finite.
  const at::Tensor defined = (count >= 2) & (xx > 0) & (yy > 0);
  const at::Tensor correlation = (dx * dy).sum() / (xx * yy).clamp_min(1e-300).sqrt();
  return at::where(defined, correlation, at::zeros_like(correlation)).to(a.scalar_type());
}

at::Tensor covered_depth_l1_autograd(const at::Tensor& depth, const at::Tensor& alpha,
                                     const at::Tensor& reference) {
  check_loss_inputs("covered depth L1", depth, reference);
  check_loss_inputs("covered depth L1 (alpha)", depth, alpha.detach());
  if (!depth.device().is_cpu())
    return covered_depth_l1_from_ops(depth, alpha, reference);  // the kernel reads host memory
  return CoveredDepthL1Function::apply(depth, alpha, reference);
}

at::Tensor covered_depth_l1_from_ops(const at::Tensor& depth, const at::Tensor& alpha,
                                     const at::Tensor& reference) {
  const at::Tensor counted =
      ((alpha.detach() >= kDepthCoverageAlpha) & (reference > 0)).to(depth.scalar_type());
  // The clamp keeps the expected depth finite where alpha vanishes, off the counted pixels.
  const at::Tensor expected = depth / alpha.clamp_min(1e-6);
  return ((expected - reference).abs() * counted).sum() / counted.sum().clamp_min(1);
}

at::Tensor photometric_autograd(const at::Tensor& render, const at::Tensor& target,
                                double dssim_weight) {
  check_loss_inputs("photometric loss", render, target);
  chw_shape(render, "photometric loss");
  if (!render.device().is_cpu()) {
    require_ssim_kernel_for(render, "photometric loss");
    const at::Tensor l1 = (render - target).abs().mean();
    return (1 - dssim_weight) * l1 + dssim_weight * (1 - ssim_autograd(render, target).mean);
  }
  // The guided loss with the whole share on the target: the same per-pixel terms in one pass.
  return guided_texture_autograd(render, at::Tensor(), target,
                                 at::zeros(render.sizes().slice(1), render.options()),
                                 dssim_weight);
}

at::Tensor guided_texture_autograd(const at::Tensor& render, const at::Tensor& internal,
                                   const at::Tensor& external, const at::Tensor& internal_share,
                                   double dssim_weight) {
  if (!internal.defined() && !external.defined())
    fail("guided texture: neither the internal nor the external image is given");
  if (internal.defined()) check_loss_inputs("guided texture (internal)", render, internal);
  if (external.defined()) check_loss_inputs("guided texture (external)", render, external);
  const auto expected = render.sizes().slice(1);
  if (!internal_share.defined() || internal_share.sizes() != expected ||
      internal_share.scalar_type() != render.scalar_type())
    fail("guided texture: the internal share must be a {} map of the render's dtype",
         c10::str(expected));
  if (!render.device().is_cpu()) {  // the kernel reads host memory
    require_ssim_kernel_for(render, "guided texture");
    return guided_texture_from_ops(render, internal, external, internal_share, dssim_weight);
  }
  const auto given = [](const at::Tensor& t) { return t.defined() ? t : at::empty({0}); };
  return GuidedTextureFunction::apply(render, given(internal), given(external), internal_share,
                                      dssim_weight);
}

at::Tensor guided_texture_from_ops(const at::Tensor& render, const at::Tensor& internal,
                                   const at::Tensor& external, const at::Tensor& internal_share,
                                   double dssim_weight) {
  const double pixels = double(internal_share.numel());
  // mean_p share(p) * ((1 - w) * l1_map(p) + w * (1 - ssim_map(p))) against one reference.
  const auto term = [&](const at::Tensor& reference, const at::Tensor& share) {
    const at::Tensor l1_map = (render - reference).abs().mean(0);
    const at::Tensor ssim_map = ssim_autograd(render, reference).map;
    return (share * ((1 - dssim_weight) * l1_map + dssim_weight * (1 - ssim_map))).sum() / pixels;
  };
  // Each reference given is evaluated, even where its share is zero: checking the share would
  // read it back from the GPU every step.
  at::Tensor loss = at::zeros({}, render.options());
  if (internal.defined()) loss = loss + term(internal, internal_share);
  if (external.defined()) loss = loss + term(external, 1 - internal_share);
  return loss;
}

}  // namespace iesrgs::loss
