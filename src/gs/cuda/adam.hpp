#pragma once
// The optimizer's fused Adam step (gs/adam.hpp) over device arrays, one thread per value.
#include <cstdint>

struct CUstream_st;

namespace iesrgs::gs::cuda {

// As the CPU optimizer's per-group pass: updates param, first and second in place from grad.
void adam_update(float* param, const float* grad, float* first, float* second, int64_t count,
                 float step_size, float bias2_sqrt, CUstream_st* stream = nullptr);

}  // namespace iesrgs::gs::cuda
