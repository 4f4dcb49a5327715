// libFuzzer harness for the transforms.json parsers (nerfstudio and Blender). Any input must
// either parse or throw iesrgs::Error; every camera that comes out must be usable downstream.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/transforms.hpp"

namespace {

using iesrgs::Camera;

// Images are never read: a fixed header stands in for the frames without w and h.
iesrgs::ImageHeader fake_header(const std::filesystem::path&) {
  return {64, 48};
}

bool finite(const iesrgs::Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

bool usable(const Camera& camera) {
  const iesrgs::Intrinsics& k = camera.stored;
  return k.width > 0 && k.height > 0 && k.fx > 0 && std::isfinite(k.fx) && k.fy > 0 &&
         std::isfinite(k.fy) && std::isfinite(k.cx) && std::isfinite(k.cy) &&
         finite(camera.translation) && finite(camera.center()) && !camera.image_path.empty();
}

void check(const std::vector<Camera>& cameras) {
  if (cameras.empty()) std::abort();
  for (const Camera& camera : cameras)
    if (!usable(camera)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    check(iesrgs::parse_nerfstudio_transforms(
              text, "scene/transforms.json", {}, fake_header,
              [](const std::filesystem::path&) { return iesrgs::PointCloud{}; })
              .cameras);
  } catch (const iesrgs::Error&) {
  }
  try {
    check(iesrgs::parse_blender_transforms(text, "scene/transforms_train.json",
                                           iesrgs::Split::Train, fake_header));
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
