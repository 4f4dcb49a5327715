#pragma once
// COLMAP sparse models (cameras, images, points3D) in binary and text form, byte-compatible with
// COLMAP's own readers and writers.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "io/scene.hpp"

namespace iesrgs {

struct ColmapCamera {
  uint32_t id = 0;
  std::string model;  // any COLMAP model name; scenes accept the pinhole and OpenCV-like ones
  uint64_t width = 0, height = 0;
  std::vector<double> params;  // in COLMAP's order for the model
};

struct ColmapObservation {
  double x = 0, y = 0;      // pixel coordinates, upper-left corner of the image at (0, 0)
  int64_t point3d_id = -1;  // -1 when untriangulated
};

struct ColmapImage {
  uint32_t id = 0;
  double qw = 1, qx = 0, qy = 0, qz = 0;  // world-to-camera rotation
  double tx = 0, ty = 0, tz = 0;          // world-to-camera translation
  uint32_t camera_id = 0;
  std::string name;  // path relative to the images folder
  std::vector<ColmapObservation> observations;
};

struct ColmapTrackElement {
  uint32_t image_id = 0;
  uint32_t point2d_index = 0;  // into that image's observations
};

struct ColmapPoint {
  uint64_t id = 0;
  double x = 0, y = 0, z = 0;
  uint8_t r = 0, g = 0, b = 0;
  double error = 0;
  std::vector<ColmapTrackElement> track;
};

struct ColmapModel {
  std::map<uint32_t, ColmapCamera> cameras;
  std::map<uint32_t, ColmapImage> images;
  std::vector<ColmapPoint> points;
};

enum class ColmapEncoding { Binary, Text };

// The contents of one model file. `source` only names the file in error messages; every
// malformed, truncated or non-finite input throws Error, and counts are checked against the
// bytes left before anything is allocated.
std::map<uint32_t, ColmapCamera> parse_colmap_cameras(std::string_view bytes,
                                                      ColmapEncoding encoding,
                                                      const std::filesystem::path& source);
std::map<uint32_t, ColmapImage> parse_colmap_images(std::string_view bytes, ColmapEncoding encoding,
                                                    const std::filesystem::path& source);
std::vector<ColmapPoint> parse_colmap_points(std::string_view bytes, ColmapEncoding encoding,
                                             const std::filesystem::path& source);

// Reads `dir`/{cameras,images,points3D}.bin, or the .txt files when there is no cameras.bin,
// and checks that every image's camera exists. A missing points3D file leaves no points.
ColmapModel read_colmap_model(const std::filesystem::path& dir);
// Write the three files atomically (COLMAP writes the text form with the same comment headers).
void write_colmap_model_binary(const std::filesystem::path& dir, const ColmapModel& model);
void write_colmap_model_text(const std::filesystem::path& dir, const ColmapModel& model);

// `root` holds sparse/0 (or sparse/) and images/; every `test_every`-th image by name is test.
// Cameras must be SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV or one of
// the equidistant fisheyes (SIMPLE_FISHEYE, FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE,
// OPENCV_FISHEYE).
Scene read_colmap_scene(const std::filesystem::path& root, const SceneOptions& options);

}  // namespace iesrgs
