#pragma once
// Where training runs: the CPU kernels, or the CUDA ones on an NVIDIA GPU. One choice per
// process, made by the command line's --device, as torch's default device is.
#include <torch/types.h>

#include <string>

namespace iesrgs {

// Whether this binary was built with the CUDA kernels (nvcc found at build time).
bool cuda_kernels_built();

// "cpu", "cuda" or "auto" (CUDA when the kernels are built and a GPU is usable, else the CPU).
// Throws Error for another name, or for "cuda" where the kernels, LibTorch's CUDA support or a
// GPU are missing, saying which.
torch::Device parse_device(const std::string& name);

// "CPU (N threads)", or the GPU's name and compute capability.
std::string describe_device(torch::Device device);

// The device that training places the model and its images on; the CPU unless set.
torch::Device compute_device();
void set_compute_device(torch::Device device);

}  // namespace iesrgs
