#include "io/colmap.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/log_once.hpp"
#include "io/atomic_file.hpp"
#include "io/colmap_codec.hpp"
#include "io/image.hpp"
#include "io/ply.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace codec = colmap_codec;

std::map<uint32_t, ColmapCamera> parse_colmap_cameras(std::string_view bytes,
                                                      ColmapEncoding encoding,
                                                      const fs::path& source) {
  return encoding == ColmapEncoding::Binary ? codec::decode_cameras_binary(bytes, source)
                                            : codec::decode_cameras_text(bytes, source);
}

std::map<uint32_t, ColmapImage> parse_colmap_images(std::string_view bytes, ColmapEncoding encoding,
                                                    const fs::path& source) {
  return encoding == ColmapEncoding::Binary ? codec::decode_images_binary(bytes, source)
                                            : codec::decode_images_text(bytes, source);
}

std::vector<ColmapPoint> parse_colmap_points(std::string_view bytes, ColmapEncoding encoding,
                                             const fs::path& source) {
  return encoding == ColmapEncoding::Binary ? codec::decode_points_binary(bytes, source)
                                            : codec::decode_points_text(bytes, source);
}

namespace {

// The three files of a model in one encoding.
struct ModelFiles {
  fs::path cameras, images, points;

  ModelFiles(const fs::path& dir, ColmapEncoding encoding) {
    const char* extension = encoding == ColmapEncoding::Binary ? ".bin" : ".txt";
    cameras = dir / (std::string("cameras") + extension);
    images = dir / (std::string("images") + extension);
    points = dir / (std::string("points3D") + extension);
  }
};

ColmapEncoding stored_encoding(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir / "cameras.bin", ec)) return ColmapEncoding::Binary;
  if (fs::exists(dir / "cameras.txt", ec)) return ColmapEncoding::Text;
  fail_file(dir, "no COLMAP model here (neither cameras.bin nor cameras.txt)");
}

void check_camera_references(const ColmapModel& model, const fs::path& images_file) {
  for (const auto& [id, image] : model.images)
    if (!model.cameras.count(image.camera_id))
      fail_file(images_file,
                fmt::format("image {} ('{}') refers to camera {}, which is not defined", id,
                            image.name, image.camera_id));
}

// All three files are encoded before any is written, so a model that cannot be written leaves
// no partial model behind.
void write_colmap_model(const fs::path& dir, const ColmapModel& model, ColmapEncoding encoding) {
  const ModelFiles files(dir, encoding);
  std::string cameras, images, points;
  if (encoding == ColmapEncoding::Binary) {
    cameras = codec::encode_cameras_binary(model.cameras, files.cameras);
    images = codec::encode_images_binary(model.images, files.images);
    points = codec::encode_points_binary(model.points);
  } else {
    cameras = codec::encode_cameras_text(model.cameras, files.cameras);
    images = codec::encode_images_text(model.images, files.images);
    points = codec::encode_points_text(model.points);
  }
  write_file_atomically(files.cameras, cameras);
  write_file_atomically(files.images, images);
  write_file_atomically(files.points, points);
}

}  // namespace

ColmapModel read_colmap_model(const fs::path& dir) {
  const ColmapEncoding encoding = stored_encoding(dir);
  const ModelFiles files(dir, encoding);
  ColmapModel model;
  model.cameras = parse_colmap_cameras(read_file(files.cameras), encoding, files.cameras);
  model.images = parse_colmap_images(read_file(files.images), encoding, files.images);
  std::error_code ec;
  if (fs::exists(files.points, ec))
    model.points = parse_colmap_points(read_file(files.points), encoding, files.points);
  check_camera_references(model, files.images);
  return model;
}

void write_colmap_model_binary(const fs::path& dir, const ColmapModel& model) {
  write_colmap_model(dir, model, ColmapEncoding::Binary);
}

void write_colmap_model_text(const fs::path& dir, const ColmapModel& model) {
  write_colmap_model(dir, model, ColmapEncoding::Text);
}

namespace {

// Where the pinhole and distortion terms sit in a supported model's parameters; -1: the model
// has no such term (zero). The SIMPLE_ models share one focal length between x and y. The fisheye
// models' k1..k4 are those of Distortion's equidistant projection.
struct PinholeLayout {
  std::string_view model;
  int fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6;
  bool fisheye = false;
};

constexpr PinholeLayout kSupportedModels[] = {
    {"SIMPLE_PINHOLE", 0, 0, 1, 2, -1, -1, -1, -1, -1, -1, -1, -1},
    {"PINHOLE", 0, 1, 2, 3, -1, -1, -1, -1, -1, -1, -1, -1},
    {"SIMPLE_RADIAL", 0, 0, 1, 2, 3, -1, -1, -1, -1, -1, -1, -1},
    {"RADIAL", 0, 0, 1, 2, 3, 4, -1, -1, -1, -1, -1, -1},
    {"OPENCV", 0, 1, 2, 3, 4, 5, 6, 7, -1, -1, -1, -1},
    {"FULL_OPENCV", 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11},
    {"SIMPLE_FISHEYE", 0, 0, 1, 2, -1, -1, -1, -1, -1, -1, -1, -1, true},
    {"FISHEYE", 0, 1, 2, 3, -1, -1, -1, -1, -1, -1, -1, -1, true},
    {"SIMPLE_RADIAL_FISHEYE", 0, 0, 1, 2, 3, -1, -1, -1, -1, -1, -1, -1, true},
    {"RADIAL_FISHEYE", 0, 0, 1, 2, 3, 4, -1, -1, -1, -1, -1, -1, true},
    {"OPENCV_FISHEYE", 0, 1, 2, 3, 4, 5, -1, -1, 6, 7, -1, -1, true},
};

const PinholeLayout& supported_layout(const ColmapCamera& camera, const fs::path& cameras_file) {
  std::string supported;
  for (const PinholeLayout& layout : kSupportedModels) {
    if (layout.model == camera.model) return layout;
    supported += (supported.empty() ? "" : ", ") + std::string(layout.model);
  }
  fail_file(cameras_file,
            fmt::format("camera {} uses the unsupported model {} (supported: {}; undistort the "
                        "images with COLMAP's image_undistorter first)",
                        camera.id, camera.model, supported));
}

struct Lens {
  Intrinsics intrinsics;
  Distortion distortion;
};

// Parameter counts were checked against the model when the file was parsed. COLMAP's principal
// point already follows Intrinsics' convention (image corner at 0, pixel centers at +0.5).
Lens lens_of(const ColmapCamera& camera, const fs::path& cameras_file) {
  const PinholeLayout& layout = supported_layout(camera, cameras_file);
  const auto param = [&camera](int index) { return index < 0 ? 0.0 : camera.params[index]; };
  if (camera.width < 1 || camera.width > uint64_t(kMaxImageSide) || camera.height < 1 ||
      camera.height > uint64_t(kMaxImageSide))
    fail_file(cameras_file, fmt::format("camera {}: implausible image size {}x{}", camera.id,
                                        camera.width, camera.height));
  Lens lens;
  lens.intrinsics = {static_cast<int>(camera.width),
                     static_cast<int>(camera.height),
                     param(layout.fx),
                     param(layout.fy),
                     param(layout.cx),
                     param(layout.cy)};
  if (!(lens.intrinsics.fx > 0 && lens.intrinsics.fy > 0))
    fail_file(cameras_file, fmt::format("camera {}: focal length must be positive", camera.id));
  lens.distortion = {param(layout.k1), param(layout.k2), param(layout.p1),
                     param(layout.p2), param(layout.k3), param(layout.k4),
                     param(layout.k5), param(layout.k6), layout.fisheye};
  return lens;
}

// As gsplat reads a model whose images were resized after COLMAP ran: a camera whose first image
// is its size scaled, each side to within a pixel of the other's factor, takes that image's size
// and its intrinsics scaled to it. Returns whether it did. Any other size, and an image that
// cannot be read, are refused when the image is decoded.
bool fit_lens_to_image(Lens& lens, const fs::path& first_image) {
  std::error_code ec;
  if (!fs::is_regular_file(first_image, ec)) return false;
  ImageHeader header;
  try {
    header = read_image_header(first_image);
  } catch (const Error&) {
    return false;
  }
  const Intrinsics& k = lens.intrinsics;
  if (header.width == k.width && header.height == k.height) return false;
  const double sx = double(header.width) / k.width, sy = double(header.height) / k.height;
  if (std::abs(k.height * sx - header.height) >= 1 || std::abs(k.width * sy - header.width) >= 1)
    return false;
  lens.intrinsics = {header.width, header.height, k.fx * sx, k.fy * sy, k.cx * sx, k.cy * sy};
  return true;
}

Camera camera_of(const ColmapImage& image, const Lens& lens, const fs::path& root,
                 const fs::path& images_file) {
  const double norm = std::sqrt(image.qw * image.qw + image.qx * image.qx + image.qy * image.qy +
                                image.qz * image.qz);
  if (!(norm > 0 && std::isfinite(norm)))
    fail_file(images_file,
              fmt::format("image '{}': rotation quaternion cannot be normalized", image.name));
  Camera camera;
  // Rigs keep one folder per camera with the same file names in each: the folder stays in the name.
  camera.name = view_name(image.name);
  camera.image_path = root / "images" / image.name;
  camera.stored = lens.intrinsics;
  camera.intrinsics = lens.intrinsics;
  camera.distortion = lens.distortion;
  camera.rotation = quat_to_rotation(image.qw, image.qx, image.qy, image.qz);
  camera.translation = {image.tx, image.ty, image.tz};
  return camera;
}

PointCloud point_cloud_of(const std::vector<ColmapPoint>& points) {
  PointCloud cloud;
  cloud.positions.reserve(points.size());
  cloud.colors.reserve(points.size());
  for (const ColmapPoint& point : points) {
    cloud.positions.push_back({point.x, point.y, point.z});
    cloud.colors.push_back({point.r, point.g, point.b});
  }
  return cloud;
}

// As 3DGS, the SfM points start training, and its own points3D.ply (x y z, red green blue) stands
// in for a model without points3D.bin/.txt; without either, training starts from random points.
PointCloud sfm_points(const ColmapModel& model, const ModelFiles& files) {
  std::error_code ec;
  if (fs::exists(files.points, ec)) return point_cloud_of(model.points);
  const fs::path ply = files.points.parent_path() / "points3D.ply";
  if (fs::exists(ply, ec)) return read_point_ply(ply);
  warn_once(
      fmt::format("{}: not found, nor points3D.ply beside it, so training starts from "
                  "random points",
                  files.points.string()));
  return {};
}

fs::path model_dir(const fs::path& root) {
  std::error_code ec;
  const fs::path first = root / "sparse" / "0";
  return fs::is_directory(first, ec) ? first : root / "sparse";
}

// Each image, or at --downscale k its copy in images_<k>/, which is all such a run reads: a capture
// may keep only the copies. Looked for as the scene loads, not when a stage reaches the view.
void require_images_or_copies(const std::vector<Camera>& cameras, const fs::path& root,
                              int downscale, const fs::path& images_file) {
  for (const Camera& camera : cameras) {
    std::error_code ec;
    const fs::path copy = downscaled_copy(root, camera.image_path, downscale).file;
    if (fs::is_regular_file(camera.image_path, ec) ||
        (!copy.empty() && fs::is_regular_file(copy, ec)))
      continue;
    fail_file(images_file, copy.empty()
                               ? fmt::format("image {} not found", camera.image_path.string())
                               : fmt::format("image {} not found, nor its copy {}",
                                             camera.image_path.string(), copy.string()));
  }
}

}  // namespace

Scene read_colmap_scene(const fs::path& root, const SceneOptions& options) {
  if (options.test_every < 1) fail("--test-every must be at least 1, got {}", options.test_every);
  const fs::path dir = model_dir(root);
  const ColmapModel model = read_colmap_model(dir);
  const ModelFiles files(dir, stored_encoding(dir));

  std::map<uint32_t, Lens> lenses;  // of the cameras images use: others may be any model
  for (const auto& [id, image] : model.images)
    if (!lenses.count(image.camera_id))
      lenses[image.camera_id] = lens_of(model.cameras.at(image.camera_id), files.cameras);

  std::vector<const ColmapImage*> images;
  for (const auto& [id, image] : model.images) images.push_back(&image);
  // Stable: equal names keep their id order, which the error below names.
  std::stable_sort(images.begin(), images.end(),
                   [](const ColmapImage* a, const ColmapImage* b) { return a->name < b->name; });
  // One file posed twice: its copies would fall into both splits, the test views among the
  // training images.
  for (size_t i = 1; i < images.size(); ++i)
    if (images[i]->name == images[i - 1]->name)
      fail_file(files.images, fmt::format("image '{}' is listed twice (ids {} and {})",
                                          images[i]->name, images[i - 1]->id, images[i]->id));
  std::set<uint32_t> seen;
  size_t fitted = 0;
  std::string first_fit;  // for the warning
  for (const ColmapImage* image : images) {
    if (!seen.insert(image->camera_id).second) continue;
    Lens& lens = lenses.at(image->camera_id);
    const Intrinsics before = lens.intrinsics;
    if (!fit_lens_to_image(lens, root / "images" / image->name)) continue;
    if (fitted++ == 0)
      first_fit =
          fmt::format("camera {}, {}x{}, whose {} is {}x{}", image->camera_id, before.width,
                      before.height, image->name, lens.intrinsics.width, lens.intrinsics.height);
  }
  if (fitted > 0)
    warn_once(
        fmt::format("{}: {} of its cameras are not the size of their images but that size "
                    "scaled; their intrinsics are scaled to the images (first: {})",
                    files.cameras.string(), fitted, first_fit));

  Scene scene;
  scene.root = root;
  scene.format = "colmap";
  scene.synthetic = false;
  for (size_t i = 0; i < images.size(); ++i) {
    Camera camera = camera_of(*images[i], lenses.at(images[i]->camera_id), root, files.images);
    camera.split = i % options.test_every == 0 ? Split::Test : Split::Train;
    scene.cameras.push_back(std::move(camera));
  }
  require_images_or_copies(scene.cameras, root, options.downscale, files.images);
  scene.points = sfm_points(model, files);
  return scene;
}

}  // namespace iesrgs
