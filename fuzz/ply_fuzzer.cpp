// Any byte string must either parse into a consistent SplatCloud or throw iesrgs::Error.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/error.hpp"
#include "io/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const iesrgs::SplatCloud cloud =
        iesrgs::parse_ply(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.ply");
    const size_t rest = size_t((cloud.sh_degree + 1) * (cloud.sh_degree + 1) - 1);
    const size_t n = cloud.size();
    if (cloud.positions.size() != 3 * n || cloud.sh_dc.size() != 3 * n ||
        cloud.sh_rest.size() != 3 * rest * n || cloud.opacity.size() != n ||
        cloud.log_scales.size() != 3 * n || cloud.rotations.size() != 4 * n ||
        (cloud.has_filter_3d() && cloud.filter_3d.size() != n))
      std::abort();
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
