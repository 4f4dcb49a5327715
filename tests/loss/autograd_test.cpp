#include "loss/autograd.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <utility>
#include <vector>

#include "loss/ssim.hpp"
#include "support/cuda_device.hpp"
#include "support/expect_error.hpp"

namespace iesrgs::loss {
namespace {

// SSIM of (C, H, W) images written with torch ops, as 3DGS writes it (grouped conv2d with the
// 11x11 Gaussian window, padding 5): returns the scalar and the channel-averaged map.
std::pair<at::Tensor, at::Tensor> torch_ops_ssim(const at::Tensor& x, const at::Tensor& y) {
  const int64_t channels = x.size(0);
  at::Tensor gauss = torch::exp(-(torch::arange(11, x.options()) - 5).pow(2) / 4.5);
  gauss = gauss / gauss.sum();
  const at::Tensor window = torch::outer(gauss, gauss).expand({channels, 1, 11, 11}).contiguous();
  const auto conv = [&](const at::Tensor& t) {
    return torch::conv2d(t, window, {}, /*stride=*/1, /*padding=*/5, /*dilation=*/1, channels);
  };
  const at::Tensor a = x.unsqueeze(0), b = y.unsqueeze(0);
  const at::Tensor mu1 = conv(a), mu2 = conv(b);
  const at::Tensor var1 = conv(a * a) - mu1 * mu1, var2 = conv(b * b) - mu2 * mu2;
  const at::Tensor cov = conv(a * b) - mu1 * mu2;
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  const at::Tensor map =
      (2 * mu1 * mu2 + c1) * (2 * cov + c2) / ((mu1 * mu1 + mu2 * mu2 + c1) * (var1 + var2 + c2));
  return {map.mean(), map.mean(1)[0]};
}

at::Tensor torch_ops_pearson(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask) {
  const at::Tensor da = a.masked_select(mask) - a.masked_select(mask).mean();
  const at::Tensor db = b.masked_select(mask) - b.masked_select(mask).mean();
  return (da * db).sum() / torch::sqrt((da * da).sum() * (db * db).sum());
}

struct Images {
  at::Tensor x, y, weight;  // weight: (H, W) upstream gradient of the map
};

Images random_images(at::ScalarType dtype) {
  torch::manual_seed(1);
  const auto options = torch::TensorOptions().dtype(dtype);
  Images images{torch::rand({3, 23, 31}, options), torch::rand({3, 23, 31}, options),
                torch::randn({23, 31}, options)};
  // A flat block, where the window variances vanish.
  images.x.slice(1, 0, 12).slice(2, 0, 12).fill_(0.9);
  images.y.slice(1, 0, 12).slice(2, 0, 12).fill_(0.4);
  return images;
}

// d/dx of 0.3 * mean + sum(weight * map), both outputs used.
template <typename Ssim>
at::Tensor composed_gradient(const Images& images, Ssim&& ssim_fn) {
  const at::Tensor x = images.x.detach().clone().requires_grad_(true);
  const auto [mean, map] = ssim_fn(x, images.y);
  (0.3 * mean + (map * images.weight).sum()).backward();
  return x.grad();
}

double max_difference(const at::Tensor& a, const at::Tensor& b) {
  return (a.to(at::kDouble) - b.to(at::kDouble)).abs().max().item<double>();
}

std::pair<at::Tensor, at::Tensor> kernel_ssim(const at::Tensor& x, const at::Tensor& y) {
  const SsimTensors out = ssim_autograd(x, y);
  return {out.mean, out.map};
}

TEST(SsimAutograd, MatchesTorchOpsInDouble) {
  const Images images = random_images(at::kDouble);
  const auto [mean, map] = kernel_ssim(images.x, images.y);
  const auto [expected_mean, expected_map] = torch_ops_ssim(images.x, images.y);
  EXPECT_LT(max_difference(mean, expected_mean), 1e-12);
  EXPECT_LT(max_difference(map, expected_map), 1e-12);
  EXPECT_LT(max_difference(composed_gradient(images, kernel_ssim),
                           composed_gradient(images, torch_ops_ssim)),
            1e-10);
}

TEST(SsimAutograd, FloatMatchesTorchOpsInDouble) {
  const Images images = random_images(at::kFloat);
  const Images in_double{images.x.to(at::kDouble), images.y.to(at::kDouble),
                         images.weight.to(at::kDouble)};
  const auto [mean, map] = kernel_ssim(images.x, images.y);
  EXPECT_EQ(map.scalar_type(), at::kFloat);
  const auto [expected_mean, expected_map] = torch_ops_ssim(in_double.x, in_double.y);
  EXPECT_LT(max_difference(mean, expected_mean), 1e-6);
  EXPECT_LT(max_difference(map, expected_map), 1e-5);
  // In float, the flat block's gradient is the difference of terms ~1/C2 times larger: the
  // kernel may not lose more there than torch's own float autograd does.
  const at::Tensor expected = composed_gradient(in_double, torch_ops_ssim);
  const double error = max_difference(composed_gradient(images, kernel_ssim), expected);
  EXPECT_LT(error, 1e-4 * expected.abs().max().item<double>());
  EXPECT_LE(error, max_difference(composed_gradient(images, torch_ops_ssim), expected));
}

TEST(SsimAutograd, GradientIsTheRawBackward) {
  const Images images = random_images(at::kFloat);
  const ImageShape shape{31, 23, 3};
  const at::Tensor weight = (images.weight + 0.3 / double(shape.pixels())).contiguous();
  std::vector<float> partials(ssim_partials_size(shape));
  at::Tensor expected = torch::zeros_like(images.x);
  ssim<float>(images.x.data_ptr<float>(), images.y.data_ptr<float>(), shape, nullptr,
              partials.data());
  ssim_backward<float>(images.x.data_ptr<float>(), images.y.data_ptr<float>(), shape,
                       partials.data(), weight.data_ptr<float>(), expected.data_ptr<float>());
  EXPECT_LT(max_difference(composed_gradient(images, kernel_ssim), expected), 1e-7);
}

TEST(SsimAutograd, CudaMatchesCpu) {
  IESRGS_SKIP_WITHOUT_CUDA();
  const Images images = random_images(at::kFloat);
  const Images on_gpu{images.x.to(torch::kCUDA), images.y.to(torch::kCUDA),
                      images.weight.to(torch::kCUDA)};
  const auto [mean, map] = kernel_ssim(on_gpu.x, on_gpu.y);
  const auto [expected_mean, expected_map] = kernel_ssim(images.x, images.y);
  ASSERT_TRUE(map.is_cuda());
  EXPECT_LT(max_difference(mean.cpu(), expected_mean), 1e-6);
  EXPECT_LT(max_difference(map.cpu(), expected_map), 1e-5);
  EXPECT_LT(testing::relative_difference(composed_gradient(on_gpu, kernel_ssim),
                                         composed_gradient(images, kernel_ssim)),
            1e-5);
}

// Device tensors take the tensor-ops version.
TEST(PearsonAutograd, CudaTensorsGiveTheCpuResult) {
  IESRGS_SKIP_WITHOUT_CUDA();
  torch::manual_seed(2);
  const at::Tensor a = torch::rand({9, 7}), b = torch::rand({9, 7});
  const at::Tensor mask = torch::rand({9, 7}) > 0.3;
  const at::Tensor x = a.clone().requires_grad_(true);
  const at::Tensor x_gpu = a.to(torch::kCUDA).requires_grad_(true);
  pearson_autograd(x, b, mask).backward();
  const at::Tensor correlation = pearson_autograd(x_gpu, b.to(torch::kCUDA), mask.to(torch::kCUDA));
  correlation.backward();
  EXPECT_TRUE(correlation.is_cuda());
  ASSERT_TRUE(x_gpu.grad().is_cuda());
  EXPECT_LT(max_difference(x_gpu.grad().cpu(), x.grad()), 1e-7);
}

TEST(SsimAutograd, MeanAloneAndNonContiguousInput) {
  const Images images = random_images(at::kDouble);
  const at::Tensor x_hwc = images.x.permute({1, 2, 0}).contiguous().requires_grad_(true);
  const at::Tensor x = x_hwc.permute({2, 0, 1});  // (C, H, W) view, not contiguous
  ssim_autograd(x, images.y).mean.backward();
  const at::Tensor reference = images.x.detach().clone().requires_grad_(true);
  torch_ops_ssim(reference, images.y).first.backward();
  EXPECT_LT(max_difference(x_hwc.grad().permute({2, 0, 1}), reference.grad()), 1e-12);
}

TEST(SsimAutograd, BadInputsAreErrors) {
  const at::Tensor image = torch::rand({3, 8, 9});
  EXPECT_EQ(testing::error_message([&] {
              ssim_autograd(image, torch::rand({1, 8, 9}));
            }),
            "ssim: target shape [1, 8, 9] differs from [3, 8, 9]");
  EXPECT_EQ(testing::error_message([&] { ssim_autograd(image[0], image[0]); }),
            "ssim: image shape [8, 9] is not (C, H, W)");
  EXPECT_EQ(
      testing::error_message([&] { ssim_autograd(image, image.clone().requires_grad_(true)); }),
      "ssim: the target must not require grad");
  EXPECT_EQ(testing::error_message([&] { ssim_autograd(image, image.to(at::kDouble)); }),
            "ssim: target dtype Double differs from Float");
  EXPECT_EQ(testing::error_message([&] { ssim_autograd(image.to(at::kInt), image.to(at::kInt)); }),
            "ssim: dtype Int is not float32 or float64");
  // A device with no kernel, rather than the CPU kernel reading memory that is not the host's.
  const at::Tensor elsewhere = torch::empty({3, 8, 9}, torch::Device(torch::kMeta));
  EXPECT_EQ(testing::error_message([&] { ssim_autograd(elsewhere, elsewhere); }),
            "ssim: this build has no kernel for Float tensors on meta");
  EXPECT_EQ(testing::error_message([&] {
              guided_texture_autograd(elsewhere, {}, elsewhere,
                                      torch::zeros({8, 9}, torch::Device(torch::kMeta)), 0.2);
            }),
            "guided texture: this build has no kernel for Float tensors on meta");
  EXPECT_EQ(testing::error_message([&] { ssim_autograd(image, image.to(torch::kMeta)); }),
            "ssim: the target is on meta, the value on cpu");
}

TEST(PearsonAutograd, MatchesTorchOpsWithAndWithoutMask) {
  torch::manual_seed(2);
  const auto options = torch::TensorOptions().dtype(at::kDouble);
  const at::Tensor a = torch::rand({17, 19}, options), b = torch::rand({17, 19}, options) + a;
  const at::Tensor mask = torch::rand({17, 19}) > 0.3;
  for (const at::Tensor& m : {mask, torch::ones({17, 19}, torch::kBool)}) {
    const at::Tensor x = a.clone().requires_grad_(true), ref = a.clone().requires_grad_(true);
    const at::Tensor loss = 1 - pearson_autograd(x, b, m.all().item<bool>() ? at::Tensor() : m);
    const at::Tensor expected = 1 - torch_ops_pearson(ref, b, m);
    EXPECT_LT(max_difference(loss, expected), 1e-12);
    loss.backward();
    expected.backward();
    EXPECT_LT(max_difference(x.grad(), ref.grad()), 1e-12);
  }
}

TEST(PearsonAutograd, FloatMatchesTorchOpsInDouble) {
  torch::manual_seed(3);
  const at::Tensor a = torch::rand({40, 30}) + 5, b = torch::rand({40, 30}) - a;
  const at::Tensor mask = torch::rand({40, 30}) > 0.5;
  const at::Tensor x = a.clone().requires_grad_(true);
  const at::Tensor ref = a.to(at::kDouble).requires_grad_(true);
  pearson_autograd(x, b, mask).backward();
  torch_ops_pearson(ref, b.to(at::kDouble), mask).backward();
  EXPECT_LT(max_difference(x.grad(), ref.grad()), 1e-5);
}

// Value and gradient of pearson_autograd's kernel and of pearson_from_ops.
std::pair<at::Tensor, at::Tensor> pearson_with_gradient(bool ops, const at::Tensor& a,
                                                        const at::Tensor& b,
                                                        const at::Tensor& mask) {
  const at::Tensor x = a.clone().requires_grad_(true);
  const at::Tensor correlation = ops ? pearson_from_ops(x, b, mask) : pearson_autograd(x, b, mask);
  correlation.backward();
  return {correlation.detach(), x.grad()};
}

TEST(PearsonAutograd, TensorOpsMatchTheKernel) {
  torch::manual_seed(4);
  const at::Tensor a = torch::rand({21, 16}) + 3, b = torch::rand({21, 16}) - 0.5 * a;
  const at::Tensor some = torch::rand({21, 16}) > 0.4;
  at::Tensor one = torch::zeros({21, 16}, torch::kBool);
  one[3][5] = true;
  // A constant side and a single entry leave the correlation undefined: 0, with a zero gradient.
  // A fractional mask selects every nonzero entry, on either path.
  const std::vector<std::pair<at::Tensor, at::Tensor>> cases = {
      {a, some},
      {a, some.to(at::kFloat) * 0.5},
      {a, torch::ones({21, 16}, torch::kBool)},
      {torch::full({21, 16}, 2.f), some},
      {a, one}};
  for (const auto& [values, mask] : cases) {
    const auto [expected, expected_grad] = pearson_with_gradient(false, values, b, mask);
    const auto [actual, actual_grad] = pearson_with_gradient(true, values, b, mask);
    EXPECT_EQ(actual.scalar_type(), at::kFloat);
    EXPECT_LT(max_difference(actual, expected), 1e-6);
    EXPECT_LT(max_difference(actual_grad, expected_grad), 1e-6);
    EXPECT_TRUE(torch::isfinite(actual_grad).all().item<bool>());
  }
}

// A render's depth and alpha, some pixels under-covered, and a reference with holes (0).
struct DepthMaps {
  at::Tensor depth, alpha, reference;
};

DepthMaps depth_maps(at::ScalarType dtype) {
  torch::manual_seed(5);
  const at::Tensor alpha = torch::rand({17, 13}, dtype);
  const at::Tensor depth = alpha * (2 + 3 * torch::rand({17, 13}, dtype));
  const at::Tensor reference =
      (2 + 3 * torch::rand({17, 13}, dtype)) * (torch::rand({17, 13}) > 0.2).to(dtype);
  return {depth, alpha, reference};
}

// Value and gradients (depth, alpha) of li times the term, by the kernel or the tensor ops.
std::vector<at::Tensor> depth_l1_with_gradients(bool ops, const DepthMaps& maps) {
  const at::Tensor depth = maps.depth.clone().requires_grad_(true);
  const at::Tensor alpha = maps.alpha.clone().requires_grad_(true);
  const at::Tensor l1 = ops ? covered_depth_l1_from_ops(depth, alpha, maps.reference)
                            : covered_depth_l1_autograd(depth, alpha, maps.reference);
  (1e-3 * l1).backward();
  return {l1.detach(), depth.grad(), alpha.grad()};
}

TEST(CoveredDepthL1Autograd, KernelMatchesTensorOps) {
  const std::vector<at::Tensor> kernel = depth_l1_with_gradients(false, depth_maps(at::kDouble));
  const std::vector<at::Tensor> ops = depth_l1_with_gradients(true, depth_maps(at::kDouble));
  EXPECT_GT(kernel[0].item<double>(), 0);
  EXPECT_GT(kernel[2].abs().max().item<double>(), 0);
  for (int i = 0; i < 3; ++i) EXPECT_LT(max_difference(kernel[i], ops[i]), 1e-12) << i;
}

// Training in float takes the same steps with the kernel as with the tensor ops.
TEST(CoveredDepthL1Autograd, FloatGradientIsTheTensorOpsToTheBit) {
  const std::vector<at::Tensor> kernel = depth_l1_with_gradients(false, depth_maps(at::kFloat));
  const std::vector<at::Tensor> ops = depth_l1_with_gradients(true, depth_maps(at::kFloat));
  EXPECT_LT(max_difference(kernel[0], ops[0]), 1e-6);
  EXPECT_TRUE(torch::equal(kernel[1], ops[1]));
  EXPECT_TRUE(torch::equal(kernel[2], ops[2]));
}

// Device tensors take the tensor-ops version.
TEST(CoveredDepthL1Autograd, CudaTensorsGiveTheCpuResult) {
  IESRGS_SKIP_WITHOUT_CUDA();
  const DepthMaps maps = depth_maps(at::kFloat);
  const DepthMaps on_gpu{maps.depth.cuda(), maps.alpha.cuda(), maps.reference.cuda()};
  const std::vector<at::Tensor> cpu = depth_l1_with_gradients(false, maps);
  const std::vector<at::Tensor> gpu = depth_l1_with_gradients(false, on_gpu);
  EXPECT_TRUE(gpu[0].is_cuda());
  for (int i = 0; i < 3; ++i) EXPECT_LT(max_difference(gpu[i].cpu(), cpu[i]), 1e-6) << i;
}

TEST(CoveredDepthL1Autograd, MismatchedShapesAreRefused) {
  const DepthMaps maps = depth_maps(at::kFloat);
  const std::string message = testing::error_message(
      [&] { covered_depth_l1_autograd(maps.depth, maps.alpha, maps.reference.t()); });
  EXPECT_NE(message.find("covered depth L1"), std::string::npos) << message;
}

// The share maps of the fusion rows: the mask M (IE-SRGS), both references averaged, E alone.
std::vector<at::Tensor> texture_shares(int64_t height, int64_t width, at::ScalarType dtype) {
  torch::manual_seed(7);
  return {(torch::rand({height, width}) > 0.7).to(dtype), torch::full({height, width}, 0.5, dtype),
          torch::zeros({height, width}, dtype)};
}

// 3DGS's photometric loss written with torch ops around the SSIM of 3DGS's Python.
at::Tensor torch_ops_photometric(const at::Tensor& x, const at::Tensor& y, double dssim_weight) {
  return (1 - dssim_weight) * (x - y).abs().mean() +
         dssim_weight * (1 - torch_ops_ssim(x, y).first);
}

TEST(PhotometricAutograd, KernelMatchesTorchOps) {
  const Images images = random_images(at::kDouble);
  const at::Tensor x = images.x.clone().requires_grad_(true);
  const at::Tensor y = images.x.clone().requires_grad_(true);
  const at::Tensor kernel = photometric_autograd(x, images.y, 0.2);
  const at::Tensor ops = torch_ops_photometric(y, images.y, 0.2);
  (3 * kernel).backward();
  (3 * ops).backward();
  EXPECT_LT(max_difference(ops, kernel), 1e-12);
  EXPECT_LT(max_difference(y.grad(), x.grad()), 1e-12);
  EXPECT_EQ(testing::error_message([&] { photometric_autograd(x[0], images.y[0], 0.2); }),
            "photometric loss: image shape [23, 31] is not (C, H, W)");
}

TEST(PhotometricAutograd, CudaMatchesCpu) {
  IESRGS_SKIP_WITHOUT_CUDA();
  const Images images = random_images(at::kFloat);
  const at::Tensor x = images.x.clone().requires_grad_(true);
  const at::Tensor x_gpu = images.x.to(torch::kCUDA).requires_grad_(true);
  const at::Tensor expected = photometric_autograd(x, images.y, 0.2);
  const at::Tensor actual = photometric_autograd(x_gpu, images.y.to(torch::kCUDA), 0.2);
  expected.backward();
  actual.backward();
  EXPECT_LT(max_difference(actual.cpu(), expected), 1e-6);
  EXPECT_LT(testing::relative_difference(x_gpu.grad(), x.grad()), 1e-5);
}

TEST(GuidedTextureAutograd, TensorOpsMatchTheKernel) {
  const Images images = random_images(at::kDouble);
  const at::Tensor external = (images.y + 0.1 * torch::rand_like(images.y)).clamp(0, 1);
  for (const at::Tensor& share : texture_shares(23, 31, at::kDouble)) {
    const at::Tensor x = images.x.clone().requires_grad_(true);
    const at::Tensor y = images.x.clone().requires_grad_(true);
    const at::Tensor kernel = guided_texture_autograd(x, images.y, external, share, 0.2);
    const at::Tensor ops = guided_texture_from_ops(y, images.y, external, share, 0.2);
    kernel.backward();
    ops.backward();
    EXPECT_LT(max_difference(ops, kernel), 1e-12);
    EXPECT_LT(max_difference(y.grad(), x.grad()), 1e-12);
  }
  // The internal image is needed only where it has a share.
  EXPECT_LT(max_difference(guided_texture_from_ops(images.x, {}, external,
                                                   texture_shares(23, 31, at::kDouble)[2], 0.2),
                           guided_texture_autograd(images.x, {}, external,
                                                   texture_shares(23, 31, at::kDouble)[2], 0.2)),
            1e-12);
}

// The backward skips the product with an upstream gradient of 1; any other value scales.
TEST(GuidedTextureAutograd, UpstreamGradientScalesTheGradient) {
  const Images images = random_images(at::kDouble);
  const at::Tensor share = texture_shares(23, 31, at::kDouble)[1];
  const at::Tensor once = images.x.clone().requires_grad_(true);
  const at::Tensor scaled = images.x.clone().requires_grad_(true);
  guided_texture_autograd(once, images.y, images.y, share, 0.2).backward();
  (-2.5 * guided_texture_autograd(scaled, images.y, images.y, share, 0.2)).backward();
  EXPECT_GT(once.grad().abs().max().item<double>(), 0);
  EXPECT_LT(max_difference(scaled.grad(), -2.5 * once.grad()), 1e-15);
}

TEST(GuidedTextureAutograd, InternalAloneNeedsNoExternalImage) {
  const Images images = random_images(at::kDouble);
  const at::Tensor all_internal = torch::ones({23, 31}, at::kDouble);
  const at::Tensor x = images.x.clone().requires_grad_(true);
  const at::Tensor y = images.x.clone().requires_grad_(true);
  const at::Tensor kernel = guided_texture_autograd(x, images.y, {}, all_internal, 0.2);
  const at::Tensor ops = guided_texture_from_ops(y, images.y, {}, all_internal, 0.2);
  kernel.backward();
  ops.backward();
  EXPECT_LT(max_difference(ops, kernel), 1e-12);
  EXPECT_LT(max_difference(y.grad(), x.grad()), 1e-12);
  EXPECT_EQ(testing::error_message(
                [&] { guided_texture_autograd(images.x, images.y, {}, all_internal * 0.5, 0.2); }),
            "guided_texture_loss: external share without an image");
  EXPECT_EQ(
      testing::error_message([&] { guided_texture_autograd(images.x, {}, {}, all_internal, 0.2); }),
      "guided texture: neither the internal nor the external image is given");
}

TEST(GuidedTextureAutograd, CudaMatchesCpu) {
  IESRGS_SKIP_WITHOUT_CUDA();
  const Images images = random_images(at::kFloat);
  const at::Tensor external = (images.y + 0.1 * torch::rand_like(images.y)).clamp(0, 1);
  for (const at::Tensor& share : texture_shares(23, 31, at::kFloat)) {
    const at::Tensor x = images.x.clone().requires_grad_(true);
    const at::Tensor x_gpu = images.x.to(torch::kCUDA).requires_grad_(true);
    const at::Tensor expected = guided_texture_autograd(x, images.y, external, share, 0.2);
    const at::Tensor actual = guided_texture_autograd(
        x_gpu, images.y.to(torch::kCUDA), external.to(torch::kCUDA), share.to(torch::kCUDA), 0.2);
    expected.backward();
    actual.backward();
    EXPECT_LT(max_difference(actual.cpu(), expected), 1e-6);
    EXPECT_LT(testing::relative_difference(x_gpu.grad(), x.grad()), 1e-5);
  }
}

TEST(PearsonAutograd, MaskOfAnotherShapeIsAnError) {
  const at::Tensor a = torch::rand({4, 5});
  EXPECT_EQ(testing::error_message([&] {
              pearson_autograd(a, a, torch::ones({5, 4}) > 0);
            }),
            "pearson: mask must have shape [4, 5], not [5, 4]");
  EXPECT_EQ(testing::error_message([&] {
              pearson_autograd(a, a, torch::ones({4, 5}, torch::Device(torch::kMeta)) > 0);
            }),
            "pearson: the mask is on meta, the values on cpu");
}

}  // namespace
}  // namespace iesrgs::loss
