#include "io/transforms.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <optional>
#include <set>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "core/log_once.hpp"
#include "core/paths.hpp"
#include "io/atomic_file.hpp"
#include "io/json_file.hpp"
#include "io/ply.hpp"

namespace iesrgs {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Poses are stored as text with float precision; real files are orthonormal to about 1e-6.
constexpr double kRotationTolerance = 1e-3;

// Where a value sits, so that every message names the file and, inside a frame, its index.
struct Where {
  const fs::path& file;
  int frame = -1;  // -1: the top level

  [[noreturn]] void fail(const std::string& problem) const {
    if (frame < 0) fail_file(file, problem);
    fail_file(file, fmt::format("frame {}: {}", frame, problem));
  }
};

// A JSON value quoted and escaped for a one-line message.
std::string quoted(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

json parse_object(const std::string& text, const fs::path& json_path) {
  json document = parse_json(text, json_path);
  if (!document.is_object()) fail_file(json_path, "top level is not a JSON object");
  return document;
}

const json* find(const json& object, const char* key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

const json& require(const json& object, const char* key, const Where& where) {
  const json* value = find(object, key);
  if (!value) where.fail(fmt::format("missing \"{}\"", key));
  return *value;
}

// JSON numbers are finite: the parser rejects overflowing literals. Those beyond the float range
// are refused as the COLMAP readers refuse them: the kernels take them in single precision.
double to_number(const json& value, const char* key, const Where& where) {
  if (!value.is_number()) where.fail(fmt::format("\"{}\" must be a number", key));
  const double number = value.get<double>();
  if (!fits_float(number))
    where.fail(fmt::format("\"{}\" {} is beyond the single-precision range", key, number));
  return number;
}

int to_image_side(double side, const char* key, const Where& where) {
  if (!(side >= 1 && side <= kMaxImageSide && side == std::floor(side)))
    where.fail(fmt::format("\"{}\" must be an integer image size in [1, {}], got {}", key,
                           kMaxImageSide, side));
  return static_cast<int>(side);
}

double focal_from_angle(double angle, int side, const char* key, const Where& where) {
  if (!(angle > 0 && angle < kPi))
    where.fail(
        fmt::format("\"{}\" must be a field of view in (0, pi) radians, got {}", key, angle));
  const double focal = 0.5 * side / std::tan(0.5 * angle);
  if (!fits_float(focal)) where.fail(fmt::format("\"{}\" is too small, got {}", key, angle));
  return focal;
}

const json& read_frames(const json& document, const fs::path& json_path) {
  const Where top{json_path};
  const json& frames = require(document, "frames", top);
  if (!frames.is_array()) top.fail("\"frames\" must be an array");
  if (frames.empty()) top.fail("no frames");
  for (size_t i = 0; i < frames.size(); ++i)
    if (!frames[i].is_object()) Where{json_path, static_cast<int>(i)}.fail("not a JSON object");
  return frames;
}

std::string read_file_path(const json& frame, const Where& where) {
  const json& value = require(frame, "file_path", where);
  if (!value.is_string() || value.get_ref<const std::string&>().empty())
    where.fail("\"file_path\" must be a non-empty string");
  const std::string& path = value.get_ref<const std::string&>();
  // Control characters would break one-line messages and are no real file name.
  if (std::any_of(path.begin(), path.end(), [](unsigned char c) { return c < 0x20; }))
    where.fail("\"file_path\" contains control characters");
  return path;
}

// A 3x4 matrix (nerfstudio accepts one) has the last row of a pose implied.
bool read_4x4(const json& value, double matrix[4][4]) {
  if (!value.is_array() || (value.size() != 4 && value.size() != 3)) return false;
  const double last_row[4] = {0, 0, 0, 1};
  std::copy(last_row, last_row + 4, matrix[3]);
  for (int r = 0; r < int(value.size()); ++r) {
    const json& row = value[r];
    if (!row.is_array() || row.size() != 4) return false;
    for (int c = 0; c < 4; ++c) {
      if (!row[c].is_number()) return false;
      matrix[r][c] = row[c].get<double>();
    }
  }
  return true;
}

// Orthonormal columns and a positive determinant. The negated comparisons also reject the NaN that
// huge entries produce.
bool is_rotation(const double m[4][4]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double dot = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
      if (!(std::abs(dot - (i == j ? 1 : 0)) <= kRotationTolerance)) return false;
    }
  const Vec3 x{m[0][0], m[1][0], m[2][0]}, y{m[0][1], m[1][1], m[2][1]},
      z{m[0][2], m[1][2], m[2][2]};
  return x.cross(y).dot(z) > 0;
}

void read_pose(const json& frame, const Where& where, Camera& camera) {
  double c2w[4][4];
  if (!read_4x4(require(frame, "transform_matrix", where), c2w))
    where.fail("\"transform_matrix\" must be a 4x4 (or 3x4) array of numbers");
  if (!is_rotation(c2w)) where.fail("\"transform_matrix\" does not hold a rotation");
  opengl_c2w_to_opencv_w2c(c2w, camera.rotation, camera.translation);
  const Vec3& t = camera.translation;
  if (!fits_float(t.x) || !fits_float(t.y) || !fits_float(t.z))
    where.fail("\"transform_matrix\" position is out of range");
}

// One frame's posed camera, named after its image; intrinsics are left to the caller.
Camera posed_camera(const json& frame, const Where& where, const fs::path& image_path) {
  Camera camera;
  camera.image_path = image_path;
  camera.name = image_path.stem().string();
  read_pose(frame, where, camera);
  return camera;
}

Intrinsics centered_intrinsics(int width, int height, double fx, double fy) {
  return {width, height, fx, fy, width / 2.0, height / 2.0};
}

void require_images_exist(const std::vector<Camera>& cameras, const fs::path& json_path) {
  for (const Camera& camera : cameras) {
    std::error_code ec;
    if (!fs::is_regular_file(camera.image_path, ec))
      fail_file(json_path, fmt::format("image {} not found", camera.image_path.string()));
  }
}

// The image a frame names: the file as written when it exists, else with Windows separators
// made '/', else with the first of `extensions` that gives a file appended. Blender frames leave
// ".png" out (3DGS always appends it, even to "r_0.001"); instant-ngp tries common image
// extensions. When none exists: the path as written, with the first extension appended if it has
// none, for the error to name.
fs::path frame_image_path(const fs::path& dir, const std::string& file_path,
                          const std::vector<const char*>& extensions) {
  std::error_code ec;
  const fs::path written = (dir / file_path).lexically_normal();
  if (fs::is_regular_file(written, ec)) return written;
  std::string portable = file_path;
  std::replace(portable.begin(), portable.end(), '\\', '/');
  const fs::path path = (dir / portable).lexically_normal();
  if (fs::is_regular_file(path, ec)) return path;
  for (const char* extension : extensions) {
    fs::path candidate = path;
    if (fs::is_regular_file(candidate += extension, ec)) return candidate;
  }
  fs::path missing = written;
  if (!missing.has_extension() && extensions.size() > 0) missing += *extensions.begin();
  return missing;
}

// A frame's keys override the scene-wide ones: nerfstudio and instant-ngp allow per-frame
// intrinsics.
class FrameKeys {
 public:
  FrameKeys(const json& scene, const json& frame, const fs::path& json_path, int index)
      : scene_(scene), frame_(frame), json_path_(json_path), index_(index) {}

  const json* find(const char* key) const {
    const json* value = iesrgs::find(frame_, key);
    return value ? value : iesrgs::find(scene_, key);
  }
  bool in_frame(const char* key) const { return frame_.contains(key); }
  // Messages about `key` name the frame only when the value came from it.
  Where where(const char* key) const { return {json_path_, in_frame(key) ? index_ : -1}; }
  Where frame() const { return {json_path_, index_}; }

  std::optional<double> number(const char* key) const {
    const json* value = find(key);
    if (!value) return std::nullopt;
    return to_number(*value, key, where(key));
  }
  std::optional<std::string> string(const char* key) const {
    const json* value = find(key);
    if (!value) return std::nullopt;
    if (!value->is_string()) where(key).fail(fmt::format("\"{}\" must be a string", key));
    return value->get<std::string>();
  }

 private:
  const json& scene_;
  const json& frame_;
  const fs::path& json_path_;
  int index_;
};

// `focal_key` (in pixels) or else `angle_key` (the field of view across `side` pixels). A frame's
// own angle overrides the scene's focal, as in instant-ngp.
std::optional<double> read_focal(const FrameKeys& keys, const char* focal_key,
                                 const char* angle_key, int side) {
  const bool frame_angle = keys.in_frame(angle_key) && !keys.in_frame(focal_key);
  if (const std::optional<double> focal = frame_angle ? std::nullopt : keys.number(focal_key)) {
    if (!(*focal > 0))
      keys.where(focal_key).fail(fmt::format("\"{}\" must be positive", focal_key));
    return focal;
  }
  if (const std::optional<double> angle = keys.number(angle_key))
    return focal_from_angle(*angle, side, angle_key, keys.where(angle_key));
  return std::nullopt;
}

Intrinsics nerfstudio_intrinsics(const FrameKeys& keys, const fs::path& image_path,
                                 const ImageHeaderReader& read_header) {
  const std::optional<double> w = keys.number("w"), h = keys.number("h");
  ImageHeader header;
  if (!w || !h) header = read_header(image_path);
  const int width = w ? to_image_side(*w, "w", keys.where("w")) : header.width;
  const int height = h ? to_image_side(*h, "h", keys.where("h")) : header.height;
  const std::optional<double> fx = read_focal(keys, "fl_x", "camera_angle_x", width);
  if (!fx) keys.frame().fail("missing \"fl_x\" (or \"camera_angle_x\")");
  // instant-ngp: a single field of view means square pixels.
  const double fy = read_focal(keys, "fl_y", "camera_angle_y", height).value_or(*fx);
  Intrinsics k = centered_intrinsics(width, height, *fx, fy);
  k.cx = keys.number("cx").value_or(k.cx);
  k.cy = keys.number("cy").value_or(k.cy);
  return k;
}

// The camera models nerfstudio takes for perspective cameras (its CAMERA_MODEL_TO_TYPE), and its
// fisheye one.
constexpr const char* kSupportedModels =
    "SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, OPENCV_FISHEYE";

bool is_perspective_model(const std::string& model) {
  return model == "SIMPLE_PINHOLE" || model == "PINHOLE" || model == "SIMPLE_RADIAL" ||
         model == "RADIAL" || model == "OPENCV";
}

Distortion nerfstudio_distortion(const FrameKeys& keys) {
  // instant-ngp flags a fisheye lens beside its k1..k4 instead of naming a camera model: read
  // as OPENCV, its images would be undistorted wrongly without a word.
  if (const json* fisheye = keys.find("is_fisheye"); fisheye && *fisheye == true)
    keys.where("is_fisheye")
        .fail(fmt::format("instant-ngp's fisheye lenses (\"is_fisheye\": true) are not supported "
                          "(supported: \"camera_model\" {})",
                          kSupportedModels));
  const std::string model = keys.string("camera_model").value_or("PINHOLE");
  Distortion d;
  d.k1 = keys.number("k1").value_or(0);
  d.k2 = keys.number("k2").value_or(0);
  d.k3 = keys.number("k3").value_or(0);
  // nerfstudio's fisheye: OpenCV's, k1..k4 on the ray's angle. Its tangential terms, which
  // nerfstudio's rays apply and its splatting undistortion drops, are refused rather than guessed.
  if (model == "OPENCV_FISHEYE") {
    for (const char* tangential : {"p1", "p2"})
      if (keys.number(tangential).value_or(0) != 0)
        keys.where(tangential)
            .fail(fmt::format("\"{}\" is not supported by OPENCV_FISHEYE (supported: k1 k2 k3 k4)",
                              tangential));
    d.k4 = keys.number("k4").value_or(0);
    d.fisheye = true;
    return d;
  }
  if (!is_perspective_model(model))
    keys.where("camera_model")
        .fail(fmt::format("unsupported \"camera_model\" {} (supported: {})", quoted(json(model)),
                          kSupportedModels));
  // nerfstudio's perspective k4 is a fourth radial term of its own, OpenCV's the first of a
  // denominator.
  if (keys.number("k4").value_or(0) != 0)
    keys.where("k4").fail(
        "\"k4\" is not supported by the perspective models (supported: k1 k2 "
        "k3 p1 p2)");
  // As nerfstudio and instant-ngp, the coefficients apply whichever of these models is named: all
  // are perspective cameras to them.
  d.p1 = keys.number("p1").value_or(0);
  d.p2 = keys.number("p2").value_or(0);
  return d;
}

// Cameras paired with their file_path as written, in file order.
std::vector<std::pair<std::string, Camera>> nerfstudio_cameras(
    const json& document, const fs::path& json_path, const ImageHeaderReader& read_header) {
  const json& frames = read_frames(document, json_path);
  std::vector<std::pair<std::string, Camera>> cameras;
  for (size_t i = 0; i < frames.size(); ++i) {
    const FrameKeys keys(document, frames[i], json_path, static_cast<int>(i));
    std::string file_path = read_file_path(frames[i], keys.frame());
    Camera camera = posed_camera(
        frames[i], keys.frame(),
        frame_image_path(json_path.parent_path(), file_path, kImageExtensionSpellings));
    camera.stored = camera.intrinsics = nerfstudio_intrinsics(keys, camera.image_path, read_header);
    camera.distortion = nerfstudio_distortion(keys);
    cameras.emplace_back(std::move(file_path), std::move(camera));
  }
  return cameras;
}

// nerfstudio's split lists: the images of each split, named as frames name theirs.
struct SplitLists {
  std::vector<fs::path> train, test;
  std::string test_key;  // "test_filenames", or "val_filenames" when the test list is missing
};

std::optional<std::vector<fs::path>> read_split_list(const json& document, const char* key,
                                                     const fs::path& json_path) {
  const json* list = find(document, key);
  if (!list) return std::nullopt;
  const Where top{json_path};
  if (!list->is_array()) top.fail(fmt::format("\"{}\" must be an array of file names", key));
  std::vector<fs::path> paths;
  for (const json& name : *list) {
    if (!name.is_string() || name.get_ref<const std::string&>().empty())
      top.fail(fmt::format("\"{}\" holds {}, not a file name", key, quoted(name)));
    paths.push_back(frame_image_path(json_path.parent_path(), name.get<std::string>(),
                                     kImageExtensionSpellings));
  }
  return paths;
}

// Absent when the file lists no split. As nerfstudio, a list for test without one for training
// is an error; the test split is nerfstudio's test list, else its val list, else empty.
std::optional<SplitLists> read_split_lists(const json& document, const fs::path& json_path) {
  std::optional<std::vector<fs::path>> train =
      read_split_list(document, "train_filenames", json_path);
  SplitLists lists;
  lists.test_key = "test_filenames";
  std::optional<std::vector<fs::path>> test =
      read_split_list(document, "test_filenames", json_path);
  if (!test) {
    lists.test_key = "val_filenames";
    test = read_split_list(document, "val_filenames", json_path);
  }
  if (!train && !test) return std::nullopt;
  if (!train)
    fail_file(json_path, fmt::format("\"{}\" without \"train_filenames\": the split lists must "
                                     "name the training images too",
                                     lists.test_key));
  if (train->empty()) fail_file(json_path, "\"train_filenames\" is empty: nothing to train on");
  lists.train = std::move(*train);
  if (test) lists.test = std::move(*test);
  return lists;
}

// The frames each list names, in the frames' order; a frame in both lists is in both splits, one
// in neither is left out, as nerfstudio does. A listed image that no frame names is an error.
void assign_listed_splits(const std::vector<std::pair<std::string, Camera>>& cameras,
                          const SplitLists& lists, const fs::path& json_path,
                          std::vector<Camera>& out) {
  for (const auto& [list, split, key] :
       {std::tuple{&lists.train, Split::Train, std::string("train_filenames")},
        std::tuple{&lists.test, Split::Test, lists.test_key}}) {
    const std::set<fs::path> listed(list->begin(), list->end());
    size_t found = 0;
    for (const auto& [file_path, camera] : cameras) {
      if (!listed.count(camera.image_path)) continue;
      out.push_back(camera);
      out.back().split = split;
      ++found;
    }
    if (found == listed.size()) continue;
    for (const fs::path& path : listed)
      if (std::none_of(cameras.begin(), cameras.end(),
                       [&path](const auto& c) { return c.second.image_path == path; }))
        fail_file(json_path, fmt::format("\"{}\" names {}, which no frame's file_path does", key,
                                         path.string()));
  }
}

}  // namespace

std::vector<Camera> parse_blender_transforms(const std::string& text, const fs::path& json_path,
                                             Split split, const ImageHeaderReader& read_header) {
  const json document = parse_object(text, json_path);
  const Where top{json_path};
  const double angle_x = to_number(require(document, "camera_angle_x", top), "camera_angle_x", top);
  const json& frames = read_frames(document, json_path);
  std::vector<Camera> cameras;
  for (size_t i = 0; i < frames.size(); ++i) {
    const Where where{json_path, static_cast<int>(i)};
    const fs::path image_path =
        frame_image_path(json_path.parent_path(), read_file_path(frames[i], where), {".png"});
    cameras.push_back(posed_camera(frames[i], where, image_path));
    cameras.back().split = split;
  }
  const ImageHeader header = read_header(cameras.front().image_path);
  const double focal = focal_from_angle(angle_x, header.width, "camera_angle_x", top);
  const Intrinsics k = centered_intrinsics(header.width, header.height, focal, focal);
  for (Camera& camera : cameras) camera.stored = camera.intrinsics = k;
  return cameras;
}

fs::path common_folder(const fs::path& a, const fs::path& b) {
  fs::path common;
  for (auto i = a.begin(), j = b.begin(); i != a.end() && j != b.end() && *i == *j; ++i, ++j)
    common /= *i;
  return common;
}

// Views are named after their image's path below the folder all images share, '/' as '_', as
// COLMAP's are below images/: a rig's cam0/0000.jpg and cam1/0000.jpg are cam0_0000 and
// cam1_0000, and images of one folder keep their stem.
void name_below_common_folder(std::vector<std::pair<std::string, Camera>>& cameras) {
  if (cameras.empty()) return;
  fs::path common = cameras.front().second.image_path.parent_path();
  for (const auto& [file_path, camera] : cameras)
    common = common_folder(common, camera.image_path.parent_path());
  for (auto& [file_path, camera] : cameras)
    camera.name = view_name(camera.image_path.lexically_relative(common));
}

Scene parse_nerfstudio_transforms(const std::string& text, const fs::path& json_path,
                                  const SceneOptions& options, const ImageHeaderReader& read_header,
                                  const PointFileReader& read_points) {
  if (options.test_every < 1) fail("--test-every must be at least 1, got {}", options.test_every);
  const json document = parse_object(text, json_path);
  std::vector<std::pair<std::string, Camera>> cameras =
      nerfstudio_cameras(document, json_path, read_header);
  // The split must not depend on the order frames happen to be listed in.
  std::stable_sort(cameras.begin(), cameras.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  name_below_common_folder(cameras);
  // nerfstudio trains only where a frame's mask is white; here every pixel is trained on.
  for (const json& frame : document.at("frames"))
    if (frame.is_object() && frame.contains("mask_path")) {
      warn_once(
          fmt::format("{}: frames' mask_path is not read: every pixel of their images is "
                      "trained on and scored",
                      json_path.string()));
      break;
    }
  Scene scene;
  scene.format = "nerfstudio";
  scene.synthetic = false;
  if (const json* ply = find(document, "ply_file_path")) {
    if (!ply->is_string() || ply->get_ref<const std::string&>().empty())
      fail_file(json_path, "\"ply_file_path\" must be a file name");
    try {
      scene.points =
          read_points((json_path.parent_path() / ply->get<std::string>()).lexically_normal());
    } catch (const Error& e) {
      fail_file(json_path, fmt::format("\"ply_file_path\": {}", e.what()));
    }
  }
  if (const std::optional<SplitLists> lists = read_split_lists(document, json_path)) {
    assign_listed_splits(cameras, *lists, json_path, scene.cameras);
    return scene;
  }
  for (size_t i = 0; i < cameras.size(); ++i) {
    Camera& camera = cameras[i].second;
    camera.split = i % options.test_every == 0 ? Split::Test : Split::Train;
    scene.cameras.push_back(std::move(camera));
  }
  return scene;
}

Scene read_blender_scene(const fs::path& root, const SceneOptions&) {
  Scene scene;
  scene.format = "blender";
  scene.synthetic = true;
  bool found_any = false;
  for (const auto& [name, split] : {std::pair{"transforms_train.json", Split::Train},
                                    std::pair{"transforms_test.json", Split::Test}}) {
    const fs::path json_path = root / name;
    std::error_code ec;
    if (!fs::exists(json_path, ec)) continue;
    found_any = true;
    const std::vector<Camera> cameras =
        parse_blender_transforms(read_file(json_path), json_path, split, read_image_header);
    require_images_exist(cameras, json_path);
    scene.cameras.insert(scene.cameras.end(), cameras.begin(), cameras.end());
  }
  if (!found_any) fail_file(root / "transforms_train.json", "not found (nor transforms_test.json)");
  return scene;
}

// As nerfstudio, a point file that is not there leaves the scene without points.
PointCloud read_point_ply_if_present(const fs::path& path) {
  std::error_code ec;
  if (fs::exists(path, ec)) return read_point_ply(path);
  warn_once(fmt::format("{}: not found, so training starts from random points", path.string()));
  return {};
}

Scene read_nerfstudio_scene(const fs::path& transforms_json, const SceneOptions& options) {
  Scene scene = parse_nerfstudio_transforms(read_file(transforms_json), transforms_json, options,
                                            read_image_header, read_point_ply_if_present);
  require_images_exist(scene.cameras, transforms_json);
  return scene;
}

}  // namespace iesrgs
