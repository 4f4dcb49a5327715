#pragma once
// The bicubic baseline: PIL's bicubic filter (a = -0.5), the same resampler that makes the
// benchmark's low-resolution inputs (io/resize.hpp), so baseline and protocol agree.
#include <memory>

#include "priors/sr/sr_net.hpp"

namespace iesrgs::priors::sr {

// Any integer scale >= 1; throws Error for others.
std::unique_ptr<SrNet> make_bicubic(int scale);

}  // namespace iesrgs::priors::sr
