#include "io/scene.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "core/error.hpp"
#include "core/log_once.hpp"
#include "core/paths.hpp"
#include "io/colmap.hpp"
#include "io/transforms.hpp"
#include "io/undistort.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

constexpr double kWidestFieldOfView = 179;  // degrees

std::vector<const Camera*> Scene::split(Split which) const {
  std::vector<const Camera*> out;
  for (const Camera& camera : cameras)
    if (camera.split == which) out.push_back(&camera);
  return out;
}

SceneNormalization Scene::normalization() const {
  std::vector<Vec3> centers;
  for (const Camera* camera : split(Split::Train)) centers.push_back(camera->center());
  if (centers.empty())
    for (const Camera& camera : cameras) centers.push_back(camera.center());
  SceneNormalization norm;
  if (centers.empty()) return norm;
  for (const Vec3& c : centers) norm.center = norm.center + c * (1.0 / centers.size());
  double largest = 0;
  for (const Vec3& c : centers) largest = std::max(largest, (c - norm.center).norm());
  norm.radius = largest * 1.1;
  return norm;
}

namespace {

// Training cameras spread over less than this fraction of the scene's depth are nearly at one
// position (a forward-facing LLFF capture spreads over several percent).
constexpr double kNarrowSpread = 0.01;

enum class SceneFormat { None, Blender, Nerfstudio, NerfstudioFile, Colmap };

bool has_blender_splits(const fs::path& folder) {
  std::error_code ec;
  return fs::exists(folder / "transforms_train.json", ec) ||
         fs::exists(folder / "transforms_test.json", ec);
}

bool has_sparse(const fs::path& folder) {
  std::error_code ec;
  return fs::is_directory(folder / "sparse", ec);
}

// In 3DGS's order: a folder with sparse/ is a COLMAP scene, whatever else it holds (instant-ngp's
// colmap2nerf writes a transforms.json beside it, without the SfM points); then NeRF Synthetic's
// split files; then nerfstudio's transforms.json.
SceneFormat detect_format(const fs::path& root) {
  std::error_code ec;
  if (fs::is_regular_file(root, ec) && root.extension() == ".json")
    return SceneFormat::NerfstudioFile;
  if (has_sparse(root)) return SceneFormat::Colmap;
  if (has_blender_splits(root)) return SceneFormat::Blender;
  if (fs::exists(root / "transforms.json", ec)) return SceneFormat::Nerfstudio;
  return SceneFormat::None;
}

// The transforms files a folder read as `format` holds but that format does not read, and how to
// read them.
void warn_unread_transforms(const fs::path& root, SceneFormat format) {
  std::error_code ec;
  const bool nerfstudio = fs::exists(root / "transforms.json", ec);
  const bool splits = format == SceneFormat::Colmap && has_blender_splits(root);
  if (!nerfstudio && !splits) return;
  std::string message =
      fmt::format("{}: read as a {} scene", root.string(),
                  format == SceneFormat::Colmap ? "COLMAP (it holds sparse/)" : "NeRF Synthetic");
  if (nerfstudio)
    message += "; its transforms.json is not read (give that file's path to read it instead)";
  if (splits)
    message +=
        "; its NeRF Synthetic split files are not read (they are read from a folder "
        "without sparse/)";
  warn_once(message);
}

// A NeRF Synthetic split file read as a nerfstudio scene would take every 8th of its views for
// test, its background black, and the other split not at all.
void refuse_blender_split_file(const fs::path& file) {
  const std::string name = file.filename().string();
  if (name != "transforms_train.json" && name != "transforms_test.json" &&
      name != "transforms_val.json")
    return;
  const fs::path folder = file.parent_path();  // load_scene made the path absolute
  if (!has_blender_splits(folder))
    fail_file(file,
              "one split of a NeRF Synthetic scene, which is read from its folder's "
              "transforms_train.json and transforms_test.json; this folder holds neither");
  if (has_sparse(folder))
    fail_file(file, fmt::format("one split of a NeRF Synthetic scene, read from its folder; but "
                                "{} holds sparse/ and is read as a COLMAP scene: move the NeRF "
                                "Synthetic files to a folder of their own",
                                folder.string()));
  fail_file(file, fmt::format("one split of a NeRF Synthetic scene: give the scene's folder, {}, "
                              "which reads transforms_train.json and transforms_test.json",
                              folder.string()));
}

Scene read_any_format(const fs::path& root, const SceneOptions& options) {
  switch (detect_format(root)) {
    case SceneFormat::NerfstudioFile:
      refuse_blender_split_file(root);
      return read_nerfstudio_scene(root, options);
    case SceneFormat::Blender:
      warn_unread_transforms(root, SceneFormat::Blender);
      return read_blender_scene(root, options);
    case SceneFormat::Nerfstudio:
      return read_nerfstudio_scene(root / "transforms.json", options);
    case SceneFormat::Colmap:
      warn_unread_transforms(root, SceneFormat::Colmap);
      return read_colmap_scene(root, options);
    case SceneFormat::None:
      break;
  }
  std::error_code ec;
  if (fs::exists(root, ec) && !fs::is_directory(root, ec))
    fail_file(root, "not a scene: give a scene's folder, or its transforms .json file");
  if (!fs::is_directory(root, ec)) fail_file(root, "scene directory not found");
  fail_file(root,
            "no scene found (looked for sparse/0/, transforms_train.json, transforms_test.json, "
            "transforms.json)");
}

// One image path under two cameras, however it is spelled: a test image would be trained on, or
// one image given two poses. Symbolic links are not followed: data stores link identical images
// of distinct frames to one file.
void require_distinct_images(const Scene& scene) {
  std::map<fs::path, const Camera*> seen;
  for (const Camera& camera : scene.cameras) {
    const fs::path file = fs::absolute(camera.image_path).lexically_normal();
    const auto [it, added] = seen.emplace(file, &camera);
    if (!added)
      fail_file(scene.root,
                fmt::format("image {} is posed twice, as {} view '{}' and {} view '{}': "
                            "one image has one camera; list it once",
                            camera.image_path.string(), split_name(it->second->split),
                            it->second->name, split_name(camera.split), camera.name));
  }
}

void require_unique_names(const Scene& scene) {
  std::map<std::pair<Split, std::string>, const Camera*> seen;
  for (const Camera& camera : scene.cameras) {
    const auto [it, added] = seen.emplace(std::pair(camera.split, camera.name), &camera);
    if (!added)
      fail_file(scene.root, fmt::format("images {} and {} are both {} views named '{}', and their "
                                        "outputs would overwrite each other; rename one",
                                        it->second->image_path.string(), camera.image_path.string(),
                                        split_name(camera.split), camera.name));
  }
}

// A pinhole camera sees less than 180 degrees: a focal length that makes it nearly that wide is a
// unit mistake, and would project Gaussians to the edge of infinity. An optical axis more than the
// image's own size away from it is a unit or key mix-up, not a lens: such a view shows the model
// nowhere, and training on it "succeeds" on a blank render.
void require_pinhole_view(const Camera& camera) {
  const Intrinsics& k = camera.stored;
  const std::string intrinsics = fmt::format(
      "its camera's focal lengths {:.6g}, {:.6g} px and principal point {:.6g}, "
      "{:.6g} for a {}x{} image",
      k.fx, k.fy, k.cx, k.cy, k.width, k.height);
  if (!(std::isfinite(k.fx) && std::isfinite(k.fy) && std::isfinite(k.cx) && std::isfinite(k.cy)))
    fail_file(camera.image_path, intrinsics + ": a pinhole camera needs finite values");
  const double widest = std::max(k.fov_x(), k.fov_y()) * 180 / kPi;
  if (!(widest < kWidestFieldOfView))
    fail_file(camera.image_path,
              fmt::format("{} make a field of view of {:.4g} degrees: a pinhole camera sees less "
                          "than {} (a focal length in other units?)",
                          intrinsics, widest, kWidestFieldOfView));
  if (!(k.cx >= -k.width && k.cx <= 2.0 * k.width && k.cy >= -k.height && k.cy <= 2.0 * k.height))
    fail_file(camera.image_path,
              intrinsics +
                  ": the principal point lies more than the image's own size outside "
                  "it, so the view would show nothing its image does");
}

// The pinhole model a view is rendered with: the image's own when it has no lens distortion, else
// the widest that sees only what the lens saw (io/undistort.hpp), so that no border pixel repeats.
// False when the lens folds back before the frame's edges, where it keeps its own.
bool set_pinhole(Camera& camera) {
  camera.pinhole = camera.stored;
  if (!camera.distortion.any()) return true;
  const std::optional<Intrinsics> pinhole = pinhole_within_lens(camera.stored, camera.distortion);
  if (pinhole) camera.pinhole = *pinhole;
  return pinhole.has_value();
}

// The largest angle between a camera's optical axis and the cameras' mean axis, in radians.
double axis_spread(const std::vector<const Camera*>& cameras) {
  Vec3 mean;
  for (const Camera* camera : cameras) mean = mean + camera->axis(2);
  if (!(mean.norm() > 0)) return kPi;
  mean = mean * (1.0 / mean.norm());
  double widest = 0;
  for (const Camera* camera : cameras)
    widest = std::max(widest, std::acos(std::clamp(camera->axis(2).dot(mean), -1.0, 1.0)));
  return widest;
}

// What the training cameras look at: the SfM points (a subsample, so that the check stays cheap on
// millions), else the point their optical axes meet where they clearly converge on one: within a
// few times the cameras' spread, or with axes more than 10 degrees apart. (A forward-facing
// capture's nearly parallel axes meet anywhere, behind the cameras too.) Empty when neither is
// known.
std::vector<Vec3> looked_at_points(const Scene& scene, std::string& what) {
  constexpr size_t kMostPoints = 4096;
  constexpr double kConvergingSpreads = 3;
  constexpr double kConvergingAngle = 10 * kPi / 180;
  const std::vector<Vec3>& points = scene.points.positions;
  std::vector<Vec3> targets;
  if (!points.empty()) {
    what = "the scene's points";
    const size_t step = (points.size() + kMostPoints - 1) / kMostPoints;
    for (size_t i = 0; i < points.size(); i += step) targets.push_back(points[i]);
  } else if (const auto cameras = scene.split(Split::Train);
             const auto focus = focus_point(cameras)) {
    const SceneNormalization sphere = scene.normalization();
    if ((*focus - sphere.center).norm() <= kConvergingSpreads * sphere.radius / 1.1 ||
        axis_spread(cameras) > kConvergingAngle) {
      what = "the point their optical axes meet";
      targets.push_back(*focus);
    }
  }
  return targets;
}

// Most training cameras with (nearly) all they look at behind them: a pose convention mistaken (a
// transforms.json written with OpenCV's axes), whose views would show nothing to learn from. A
// camera inside the scene sees about half its points: it faces none away.
std::optional<std::string> camera_facing_warning(const Scene& scene) {
  constexpr double kFewestInFront = 0.1;
  std::string what;
  const std::vector<Vec3> targets = looked_at_points(scene, what);
  const std::vector<const Camera*> cameras = scene.split(Split::Train);
  if (targets.empty()) return std::nullopt;
  size_t away = 0;
  for (const Camera* camera : cameras) {
    size_t in_front = 0;
    for (const Vec3& target : targets)
      in_front += (camera->rotation * target + camera->translation).z > 0;
    away += double(in_front) < kFewestInFront * double(targets.size());
  }
  if (2 * away <= cameras.size()) return std::nullopt;
  return fmt::format(
      "{} of the {} training cameras face away from {}: their views would show none of it, and "
      "training would learn nothing{}",
      away, cameras.size(), what,
      scene.format == "colmap"
          ? ""
          : " (transforms files hold camera-to-world matrices with OpenGL's axes, x right, y up, "
            "z backward: one written with OpenCV's, z forward, turns every camera around)");
}

std::optional<std::string> camera_spread_warning(const Scene& scene) {
  const SceneNormalization sphere = scene.normalization();
  // The depth of the scene as the cameras see it: the SfM points' median distance from the
  // cameras' center, else the cameras' median distance to the point their optical axes meet.
  std::vector<double> distances;
  for (const Vec3& point : scene.points.positions)
    distances.push_back((point - sphere.center).norm());
  const std::vector<const Camera*> cameras = scene.split(Split::Train);
  if (distances.empty())
    if (const std::optional<Vec3> focus = focus_point(cameras))
      for (const Camera* camera : cameras) distances.push_back((camera->center() - *focus).norm());
  if (distances.empty()) return std::nullopt;
  const double depth = median(distances);
  const double spread = sphere.radius / 1.1;
  if (!(spread < kNarrowSpread * depth)) return std::nullopt;
  return fmt::format(
      "the {} training cameras lie within {:.3g} of their center, {:.2g} % of the scene's depth "
      "({:.3g}): views from nearly one position see little parallax, and 3DGS's position "
      "learning rate and densification sizes, which scale with that spread, will be tiny",
      cameras.size(), spread, 100 * spread / depth, depth);
}

}  // namespace

bool is_scene(const fs::path& path) {
  return detect_format(path) != SceneFormat::None;
}

void require_training_views(const Scene& scene) {
  if (scene.split(Split::Train).empty())
    fail_file(scene.root, fmt::format("no training views: all {} images are test views ({})",
                                      scene.cameras.size(),
                                      scene.format == "blender"
                                          ? "NeRF-Synthetic scenes train on transforms_train.json"
                                          : "this format holds out every --test-every-th image"));
}

void require_trainable_views(const Scene& scene) {
  require_training_views(scene);
  // 3DGS scales its position learning rate and densification by the spread of the training
  // cameras: views from one position give it none, and no position would be optimized.
  const SceneNormalization sphere = scene.normalization();
  if (sphere.radius > 1e-9 * (1 + sphere.center.norm())) {
    for (const std::string& warning : camera_warnings(scene))
      spdlog::warn("{}: {}", scene.root.string(), warning);
    return;
  }
  const size_t count = scene.split(Split::Train).size();
  const std::string views = count == 1
                                ? "a single training view, at"
                                : fmt::format("all {} training views at one position,", count);
  fail_file(scene.root, fmt::format("{} ({:.6g}, {:.6g}, {:.6g}): Gaussian splatting needs views "
                                    "from different positions, to see depth and to take the "
                                    "scene's scale from their spread",
                                    views, sphere.center.x, sphere.center.y, sphere.center.z));
}

std::vector<std::string> camera_warnings(const Scene& scene) {
  std::vector<std::string> warnings;
  for (const std::optional<std::string>& warning :
       {camera_facing_warning(scene), camera_spread_warning(scene)})
    if (warning) warnings.push_back(*warning);
  return warnings;
}

DownscaledCopy downscaled_copy(const fs::path& scene_root, const fs::path& image_path,
                               int downscale) {
  if (downscale <= 1) return {};
  std::error_code ec;
  const fs::path root = fs::is_regular_file(scene_root, ec) ? scene_root.parent_path() : scene_root;
  const fs::path relative = image_path.lexically_relative(root);
  if (relative.empty() || *relative.begin() == ".." ||
      std::next(relative.begin()) == relative.end())
    return {};
  DownscaledCopy copy;
  copy.folder = root / (relative.begin()->string() + "_" + std::to_string(downscale));
  copy.file = copy.folder;
  for (auto part = std::next(relative.begin()); part != relative.end(); ++part) copy.file /= *part;
  return copy;
}

fs::path scene_folder(const fs::path& root) {
  return fs::is_directory(root) ? root : root.parent_path();
}

void refuse_output_in_scene_folder(const fs::path& output, const Scene& scene) {
  if (resolved_path(output) != resolved_path(scene_folder(scene.root))) return;
  fail_file(output,
            "is the scene's own folder, whose files the outputs could replace; write them "
            "elsewhere (a folder inside it will do)");
}

Scene load_scene(const fs::path& given_root, const SceneOptions& options) {
  if (options.downscale < 1) fail("--downscale must be at least 1, got {}", options.downscale);
  // Absolute, so that the cached stages keyed by the scene's paths are found again from any
  // working directory.
  const fs::path root = fs::absolute(given_root).lexically_normal();
  Scene scene = read_any_format(root, options);
  if (scene.cameras.empty()) fail_file(root, "scene has no cameras");
  scene.root = root;
  require_distinct_images(scene);
  require_unique_names(scene);
  scene.background = options.background.value_or(scene.synthetic ? std::array<float, 3>{1, 1, 1}
                                                                 : std::array<float, 3>{0, 0, 0});
  scene.downscale = options.downscale;
  std::vector<const Camera*> folded;
  for (Camera& camera : scene.cameras) {
    require_pinhole_view(camera);
    if (!set_pinhole(camera)) folded.push_back(&camera);
    camera.intrinsics = camera.pinhole.scaled(1.0 / options.downscale);
    if (camera.intrinsics.width < 1 || camera.intrinsics.height < 1)
      fail_file(camera.image_path,
                fmt::format("at 1/{} of its {}x{} pixels, this view would have none; use a "
                            "smaller downscale or scale factor",
                            options.downscale, camera.stored.width, camera.stored.height));
  }
  if (!folded.empty())
    warn_once(
        fmt::format("{} of the scene's {} views ({} first): the lens cannot be undone out to "
                    "the frame's edges (its distortion folds back, or a fisheye's frame reaches "
                    "past 90 degrees), so they keep the lens's own intrinsics and show less than "
                    "it saw",
                    folded.size(), scene.cameras.size(), folded.front()->image_path.string()));
  return scene;
}

}  // namespace iesrgs
