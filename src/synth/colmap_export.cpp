#include "synth/colmap_export.hpp"

#include <algorithm>
#include <cmath>

#include "core/math.hpp"
#include "io/camera.hpp"
#include "io/viewer_cloud.hpp"

namespace iesrgs::synth {

namespace {

constexpr uint32_t kCameraId = 1;

}  // namespace

ColmapExport::ColmapExport(const RenderSettings& settings, int points_per_view)
    : settings_(settings), points_per_view_(points_per_view) {
  const double focal = settings.focal();
  model_.cameras[kCameraId] = {kCameraId,
                               "PINHOLE",
                               uint64_t(settings.width),
                               uint64_t(settings.height),
                               {focal, focal, settings.width / 2.0, settings.height / 2.0}};
}

void ColmapExport::add_view(const CameraPose& pose, const RenderedView& view,
                            const std::string& name) {
  double c2w[4][4];
  const auto matrix = pose.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) c2w[r][c] = matrix[r][c];
  Mat3 rotation;
  Vec3 translation;
  opengl_c2w_to_opencv_w2c(c2w, rotation, translation);
  const auto q = rotation_to_quat(rotation);
  ColmapImage image;
  image.id = uint32_t(model_.images.size() + 1);
  image.camera_id = kCameraId;
  image.name = name;
  image.qw = q[0], image.qx = q[1], image.qy = q[2], image.qz = q[3];
  image.tx = translation.x, image.ty = translation.y, image.tz = translation.z;

  const std::vector<double>& k = model_.cameras.at(kCameraId).params;
  const int w = settings_.width, h = settings_.height;
  // A regular pixel grid with about points_per_view samples; keep fully covered pixels only, so
  // no point sits on a silhouette between surface and background.
  const int stride = std::max(1, int(std::sqrt(double(w) * h / points_per_view_)));
  const Mat3 to_world = rotation.transposed();
  for (int y = stride / 2; y < h; y += stride) {
    for (int x = stride / 2; x < w; x += stride) {
      const float z = view.depth[size_t(y) * w + x];
      if (z <= 0 || view.rgba.at(x, y, 3) < 1.f) continue;
      const double u = x + 0.5, v = y + 0.5;
      const Vec3 in_camera{(u - k[2]) / k[0] * z, (v - k[3]) / k[1] * z, z};
      const Vec3 world = to_world * (in_camera - translation);
      ColmapPoint point;
      point.id = model_.points.size() + 1;
      point.x = world.x, point.y = world.y, point.z = world.z;
      point.r = to_byte(255.0 * view.rgba.at(x, y, 0));
      point.g = to_byte(255.0 * view.rgba.at(x, y, 1));
      point.b = to_byte(255.0 * view.rgba.at(x, y, 2));
      point.track.push_back({image.id, uint32_t(image.observations.size())});
      image.observations.push_back({u, v, int64_t(point.id)});
      model_.points.push_back(std::move(point));
    }
  }
  model_.images[image.id] = std::move(image);
}

void ColmapExport::write(const std::filesystem::path& dir) const {
  write_colmap_model_binary(dir / "sparse" / "0", model_);
}

}  // namespace iesrgs::synth
