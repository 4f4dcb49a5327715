#include "core/device.hpp"

#include <omp.h>
#include <torch/cuda.h>

#include "core/error.hpp"
#ifdef IESRGS_WITH_CUDA
#include "core/cuda/device.hpp"
#endif

namespace iesrgs {

namespace {

torch::Device& chosen_device() {
  static torch::Device device = torch::kCPU;
  return device;
}

// Why CUDA cannot be used here; empty when it can.
std::string cuda_unusable_reason() {
  if (!cuda_kernels_built()) return "this build has no CUDA kernels (nvcc was not found)";
  if (!torch::cuda::is_available())
    return "LibTorch sees no usable GPU (a CPU-only LibTorch, or no GPU or driver)";
  return {};
}

}  // namespace

bool cuda_kernels_built() {
#ifdef IESRGS_WITH_CUDA
  return true;
#else
  return false;
#endif
}

torch::Device parse_device(const std::string& name) {
  if (name == "cpu") return torch::kCPU;
  if (name == "auto") return cuda_unusable_reason().empty() ? torch::kCUDA : torch::kCPU;
  if (name == "cuda") {
    const std::string reason = cuda_unusable_reason();
    if (!reason.empty()) fail("--device cuda: {}", reason);
    return torch::kCUDA;
  }
  fail("--device: unknown device '{}' (cpu, cuda or auto)", name);
}

std::string describe_device(torch::Device device) {
#ifdef IESRGS_WITH_CUDA
  if (device.is_cuda()) return "CUDA, " + cuda::device_description();
#endif
  return fmt::format("{} ({} threads)", c10::str(device), omp_get_max_threads());
}

torch::Device compute_device() {
  return chosen_device();
}

void set_compute_device(torch::Device device) {
  chosen_device() = device;
}

}  // namespace iesrgs
