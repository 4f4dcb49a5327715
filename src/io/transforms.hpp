#pragma once
// transforms.json readers: NeRF-Synthetic / Blender and nerfstudio / instant-ngp.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io/image.hpp"
#include "io/scene.hpp"

namespace iesrgs {

// `root` holds transforms_train.json, transforms_test.json or both (a test-only folder can be
// rendered and scored), with camera_angle_x and RGBA images; transforms_val.json is ignored, as
// 3DGS does. The image size is read from the
// header of each file's first image.
Scene read_blender_scene(const std::filesystem::path& root, const SceneOptions& options);

// `transforms_json` in the nerfstudio / instant-ngp convention: per-scene or per-frame
// intrinsics (fl_x, fl_y, cx, cy, w, h or camera_angle_x/y), the perspective camera models (k1 k2
// k3 p1 p2 under any) and OPENCV_FISHEYE (k1..k4). Frames sorted by file_path; the file's split
// lists (train_filenames, test_filenames or val_filenames) set the split when it has them, else
// every `test_every`-th frame, starting with the first, is held out for test (LLFF convention). The
// points of its ply_file_path (nerfstudio's SfM points, in the frames' coordinates) start training.
Scene read_nerfstudio_scene(const std::filesystem::path& transforms_json,
                            const SceneOptions& options);

// The parsers behind the readers, on JSON text already in memory (so they can be fuzzed without
// files): `json_path` names the source in messages and anchors relative image paths. Images are
// only touched through `read_header`, for sizes the JSON does not give, and a point file through
// `read_points`; whether every image exists is left to the readers above.
using ImageHeaderReader = std::function<ImageHeader(const std::filesystem::path&)>;
using PointFileReader = std::function<PointCloud(const std::filesystem::path&)>;

// One transforms_<split>.json of a Blender scene.
std::vector<Camera> parse_blender_transforms(const std::string& text,
                                             const std::filesystem::path& json_path, Split split,
                                             const ImageHeaderReader& read_header);
Scene parse_nerfstudio_transforms(const std::string& text, const std::filesystem::path& json_path,
                                  const SceneOptions& options, const ImageHeaderReader& read_header,
                                  const PointFileReader& read_points);

}  // namespace iesrgs
