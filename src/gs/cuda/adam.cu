#include "gs/cuda/adam.hpp"

#include "core/cuda/check.hpp"
#include "gs/adam.hpp"

namespace iesrgs::gs::cuda {

namespace {

constexpr int kThreads = 256;

__global__ void adam_kernel(float* param, const float* grad, float* first, float* second,
                            int64_t count, float step_size, float bias2_sqrt) {
  const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < count) adam_update_value(param[i], grad[i], first[i], second[i], step_size, bias2_sqrt);
}

}  // namespace

void adam_update(float* param, const float* grad, float* first, float* second, int64_t count,
                 float step_size, float bias2_sqrt, CUstream_st* stream) {
  if (count <= 0) return;
  adam_kernel<<<unsigned((count + kThreads - 1) / kThreads), kThreads, 0, stream>>>(
      param, grad, first, second, count, step_size, bias2_sqrt);
  iesrgs::cuda::check(cudaGetLastError(), "adam_update");
}

}  // namespace iesrgs::gs::cuda
