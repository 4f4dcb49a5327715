// Any byte string must either parse into a consistent SplatCloud or throw iesrgs::Error; read as a
// point cloud, into as many colours as positions, or throw.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/error.hpp"
#include "io/ply.hpp"
#include "splat_cloud_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    abort_unless_consistent(iesrgs::parse_ply(bytes, "fuzz.ply"));
  } catch (const iesrgs::Error&) {
  }
  try {
    const iesrgs::PointCloud points = iesrgs::parse_point_ply(bytes, "fuzz.ply");
    if (points.colors.size() != points.positions.size()) std::abort();
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
