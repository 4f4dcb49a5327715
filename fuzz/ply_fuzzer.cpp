// Any byte string must either parse into a consistent SplatCloud or throw iesrgs::Error.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.hpp"
#include "io/ply.hpp"
#include "splat_cloud_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    abort_unless_consistent(
        iesrgs::parse_ply(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.ply"));
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
