#pragma once
// A reproducible model for timing the per-iteration bookkeeping (the optimizer step), shared by
// iesrgs_bench and `iesrgs bench adam` so that both time the same thing.
#include <cstdint>

#include "gs/model.hpp"

namespace iesrgs::gs {

// n Gaussians of SH degree 3 with seeded random parameters and a gradient on every one.
GaussianModel benchmark_model(int64_t n);

}  // namespace iesrgs::gs
