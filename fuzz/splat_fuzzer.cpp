// Any byte string must either decode into a consistent SplatCloud of finite values with unit
// quaternions or throw iesrgs::Error.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.hpp"
#include "io/splat_file.hpp"
#include "splat_cloud_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const iesrgs::SplatCloud cloud = iesrgs::parse_splat(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.splat");
    abort_unless_consistent(cloud);
    abort_unless_finite_with_unit_rotations(cloud);
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
