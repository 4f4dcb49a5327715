#pragma once
// One in-memory model of a posed capture, whatever format it came from.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/camera.hpp"
#include "io/point_cloud.hpp"

namespace iesrgs {

// Scene center and extent exactly as 3DGS's getNerfppNorm: center of the camera centers, radius
// = 1.1 x the largest distance of a camera center from it. Learning rates scale with `radius`.
struct SceneNormalization {
  Vec3 center;
  double radius = 1;
};

struct Scene {
  std::filesystem::path root;
  std::string format;  // "blender", "nerfstudio" or "colmap"
  std::vector<Camera> cameras;
  PointCloud points;                         // empty for synthetic scenes
  std::array<float, 3> background{1, 1, 1};  // rendered behind the model; RGBA images over it
  bool synthetic = false;  // object-centric with a known bounding volume (NeRF Synthetic)
  int downscale = 1;       // cameras' intrinsics are the stored ones divided by this

  std::vector<const Camera*> split(Split which) const;
  SceneNormalization normalization() const;  // from the training cameras
};

struct SceneOptions {
  int downscale = 1;  // read <images>_<k> when present, else resize
  // Unset: white for NeRF Synthetic scenes, black for captures (COLMAP, nerfstudio), as 3DGS
  // trains them (its --white_background is for the synthetic scenes).
  std::optional<std::array<float, 3>> background{};
  int test_every = 8;  // LLFF hold-out for formats without a test split
};

// Detects the format from the files present and loads cameras and points (not the images).
// Every camera's intrinsics are already at 1/downscale of the stored resolution. Throws Error
// when two cameras of a split share a name, since their outputs would overwrite each other.
Scene load_scene(const std::filesystem::path& root, const SceneOptions& options = {});

// The folder holding the scene at `root` (a scene's own root, say): the folder itself, or that of
// a transforms.json given as the scene.
std::filesystem::path scene_folder(const std::filesystem::path& root);

// Throws Error naming `output` when it is the scene's own folder, where outputs (rgb/, render.json,
// point_cloud.ply, ...) could replace the scene's own files and a later command would remove them
// as its own. A folder inside it is fine.
void refuse_output_in_scene_folder(const std::filesystem::path& output, const Scene& scene);

// Where the pre-downscaled copy of an image would be: the image's top folder below the scene root
// gets "_<k>" (COLMAP / nerfstudio convention: images/cam0/a.png -> images_2/cam0/a.png). A scene
// given as its transforms.json has that file's folder as its root. Empty when there is none to
// look for: no downscale, or an image not inside a folder of the scene.
struct DownscaledCopy {
  std::filesystem::path folder;  // images_<k>
  std::filesystem::path file;
};
DownscaledCopy downscaled_copy(const std::filesystem::path& scene_root,
                               const std::filesystem::path& image_path, int downscale);

// Whether load_scene would recognise a format at `path` (a plain folder of images is not a scene).
bool is_scene(const std::filesystem::path& path);

// Throws Error naming the scene when it has no training view (every image held out for testing).
void require_training_views(const Scene& scene);

// The same, and also when every training view is taken from one position: nothing to train on.
// Logs camera_warnings' texts.
void require_trainable_views(const Scene& scene);

// What is suspect in the training cameras, one text each: most of them facing away from what
// they look at (a pose convention mistaken), or all nearly at one position (little parallax).
std::vector<std::string> camera_warnings(const Scene& scene);

}  // namespace iesrgs
