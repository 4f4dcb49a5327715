#include "io/cameras_json.hpp"

#include <nlohmann/json.hpp>

#include "io/atomic_file.hpp"

namespace iesrgs {

std::string cameras_json(const std::vector<Camera>& cameras) {
  nlohmann::json entries = nlohmann::json::array();
  for (size_t id = 0; id < cameras.size(); ++id) {
    const Camera& camera = cameras[id];
    const Mat3 camera_to_world = camera.rotation.transposed();
    const Vec3 center = camera.center();
    nlohmann::json rotation = nlohmann::json::array();
    for (int row = 0; row < 3; ++row)
      rotation.push_back(
          {camera_to_world(row, 0), camera_to_world(row, 1), camera_to_world(row, 2)});
    entries.push_back({{"id", id},
                       {"img_name", camera.name},
                       {"width", camera.intrinsics.width},
                       {"height", camera.intrinsics.height},
                       {"position", {center.x, center.y, center.z}},
                       {"rotation", rotation},
                       {"fy", camera.intrinsics.fy},
                       {"fx", camera.intrinsics.fx}});
  }
  return entries.dump() + "\n";
}

void write_cameras_json(const std::filesystem::path& path, const std::vector<Camera>& cameras) {
  write_file_atomically(path, cameras_json(cameras));
}

}  // namespace iesrgs
