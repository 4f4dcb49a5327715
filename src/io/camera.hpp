#pragma once
// A posed pinhole camera in the OpenCV convention used everywhere inside iesrgs:
// x right, y down, z forward; world-to-camera p_cam = R * p_world + t.
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/math.hpp"

namespace iesrgs {

enum class Split { Train, Test };

// The largest image side a scene file may declare: larger is a corrupt value, not an image anyone
// trains on, and would drive huge allocations and overflow int pixel counts.
constexpr int kMaxImageSide = 1 << 16;

const char* split_name(Split split);

// A view's name: its image's path below the folder its scene names views from, without the
// extension, '/' as '_' (a rig's cam0/000.png and cam1/000.png are cam0_000 and cam1_000).
std::string view_name(const std::filesystem::path& image_below_folder);

// Lens distortion of the stored image, in the OpenCV / COLMAP models. Perspective: radial k1, k2,
// k3 over k4, k5, k6 (FULL_OPENCV's rational model; OPENCV's is k1, k2 alone), tangential p1, p2;
// all zero means the image is already pinhole. Fisheye (OPENCV_FISHEYE and its simpler kin): the
// equidistant projection, the ray at angle theta from the axis imaged at radius
// theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8); the other terms unused.
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;
  double k3 = 0, k4 = 0, k5 = 0, k6 = 0;
  bool fisheye = false;

  bool any() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || beyond_opencv(); }
  bool beyond_opencv() const { return fisheye || k3 != 0 || k4 != 0 || k5 != 0 || k6 != 0; }
  // Maps normalized undistorted coordinates (x, y) to distorted ones. Zero terms add exact zeros,
  // so an OPENCV lens maps as it did before the other terms were read.
  void apply(double x, double y, double& xd, double& yd) const {
    const double r2 = x * x + y * y;
    if (fisheye) {
      const double r = std::sqrt(r2), theta = std::atan(r), t2 = theta * theta;
      const double imaged = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))));
      const double scale = r > 1e-12 ? imaged / r : 1.0;  // theta / r -> 1 on the axis
      xd = x * scale;
      yd = y * scale;
      return;
    }
    const double radial = (1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2) /
                          (1 + k4 * r2 + k5 * r2 * r2 + k6 * r2 * r2 * r2);
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  }
  // " k3 k4 k5 k6" (" fisheye k3 k4 k5 k6" for a fisheye) for the keys of what an undistortion
  // made, or nothing for a perspective lens whose are all zero: the keys of OPENCV lenses stay
  // those made before these terms were read.
  std::string terms_beyond_opencv() const;
};

struct Intrinsics {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;

  // The same field of view at `scale` times the resolution (pixel centers at +0.5).
  Intrinsics scaled(double scale) const;
  double fov_x() const;
  double fov_y() const;
};

struct Camera {
  std::string name;  // view_name of the image (below COLMAP's images/, nerfstudio's shared
                     // folder), unique per split: renders and per-view outputs are named after it
  Split split = Split::Train;
  Intrinsics intrinsics;             // the pinhole model the renderer uses (after --downscale)
  Mat3 rotation;                     // world-to-camera
  Vec3 translation;                  // world-to-camera
  std::filesystem::path image_path;  // full-resolution image as stored
  Intrinsics stored;                 // of the image at image_path
  Distortion distortion;  // of the stored image; loading undistorts it to a pinhole image
  Intrinsics pinhole;     // the undistorted image's, at the stored size (`stored` when no lens
                          // distortion): what `intrinsics` scales, set by load_scene

  Vec3 center() const { return -(rotation.transposed() * translation); }
  // One of the camera's axes in world coordinates (0 right, 1 down, 2 forward).
  Vec3 axis(int i) const { return {rotation(i, 0), rotation(i, 1), rotation(i, 2)}; }
  // Same pose, `scale` times the resolution (rendering at s x is just another camera).
  Camera scaled(double scale) const;
};

// The point nearest to every camera's optical axis (least squares): what a capture looks at.
// None for fewer than two cameras, and when the axes are parallel (a rig of parallel cameras).
std::optional<Vec3> focus_point(const std::vector<const Camera*>& cameras);

// World-to-camera (OpenCV) from a camera-to-world matrix in the OpenGL / NeRF convention
// (x right, y up, z backward), as stored by NeRF-Synthetic and nerfstudio transforms.json.
void opengl_c2w_to_opencv_w2c(const double c2w[4][4], Mat3& rotation, Vec3& translation);

}  // namespace iesrgs
