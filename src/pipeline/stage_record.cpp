#include "pipeline/stage_record.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/atomic_file.hpp"
#include "io/file_digest.hpp"
#include "io/image.hpp"
#include "io/npy.hpp"

namespace iesrgs::pipeline {

nlohmann::json read_stage_record(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) return nlohmann::json::object();
  nlohmann::json record = nlohmann::json::parse(read_file(path), nullptr, false);
  return record.is_object() ? record : nlohmann::json::object();
}

bool cached_view_intact(const std::filesystem::path& image, const std::filesystem::path& depth,
                        int width, int height) {
  try {
    const Image8 decoded = read_image8(image);
    if (decoded.width != width || decoded.height != height) return false;
    return depth.empty() ||
           read_npy(depth).shape == std::vector<size_t>{size_t(height), size_t(width)};
  } catch (const Error&) {
    return false;
  }
}

std::string split_digest(const ViewImages& images, Split split) {
  const Scene& scene = images.scene();
  std::string key = fmt::format("background {};\n", fmt::join(scene.background, " "));
  for (const Camera* camera : scene.split(split)) {
    const Intrinsics& k = camera->intrinsics;
    const Distortion& d = camera->distortion;
    key += fmt::format("{} {} {}x{} {} {} {} {} | {} {} {} {} | {} | {} {} {};\n", camera->name,
                       images.source_digest(*camera), k.width, k.height, k.fx, k.fy, k.cx, k.cy,
                       d.k1, d.k2, d.p1, d.p2, fmt::join(camera->rotation.m, " "),
                       camera->translation.x, camera->translation.y, camera->translation.z);
  }
  return bytes_digest(key);
}

std::string points_digest(const PointCloud& points) {
  const auto bytes = [](const auto& values) {
    return std::string_view(reinterpret_cast<const char*>(values.data()),
                            values.size() * sizeof(values[0]));
  };
  return bytes_digest(fmt::format("{} {}", bytes_digest(bytes(points.positions)),
                                  bytes_digest(bytes(points.colors))));
}

}  // namespace iesrgs::pipeline
