#pragma once
// cameras.json as 3DGS writes it beside a trained model, which splat viewers read to offer the
// training views as viewpoints.
#include <filesystem>
#include <string>
#include <vector>

#include "io/camera.hpp"

namespace iesrgs {

// One entry per camera, in order: id, img_name, width, height, position (the camera centre),
// rotation (camera-to-world, rows; OpenCV axes), fx, fy.
std::string cameras_json(const std::vector<Camera>& cameras);

// cameras_json(cameras), written atomically.
void write_cameras_json(const std::filesystem::path& path, const std::vector<Camera>& cameras);

}  // namespace iesrgs
