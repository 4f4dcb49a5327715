#include "io/colmap_codec.hpp"

#include "core/error.hpp"

namespace iesrgs::colmap_codec {

namespace fs = std::filesystem;

namespace {

// COLMAP's camera models (src/colmap/sensor/models.h): binary files store the id, text files the
// name, and neither stores the parameter count.
constexpr CameraModelInfo kCameraModels[] = {
    {0, "SIMPLE_PINHOLE", 3},
    {1, "PINHOLE", 4},
    {2, "SIMPLE_RADIAL", 4},
    {3, "RADIAL", 5},
    {4, "OPENCV", 8},
    {5, "OPENCV_FISHEYE", 8},
    {6, "FULL_OPENCV", 12},
    {7, "FOV", 5},
    {8, "SIMPLE_RADIAL_FISHEYE", 4},
    {9, "RADIAL_FISHEYE", 5},
    {10, "THIN_PRISM_FISHEYE", 12},
    {11, "RAD_TAN_THIN_PRISM_FISHEYE", 16},
    {12, "SIMPLE_DIVISION", 4},
    {13, "DIVISION", 5},
    {14, "SIMPLE_FISHEYE", 3},
    {15, "FISHEYE", 4},
    {16, "EUCM", 6},
    {17, "EQUIRECTANGULAR", 2},
};

template <typename Predicate>
const CameraModelInfo* find_camera_model_if(Predicate matches) {
  for (const CameraModelInfo& model : kCameraModels)
    if (matches(model)) return &model;
  return nullptr;
}

}  // namespace

const CameraModelInfo* find_camera_model(int id) {
  return find_camera_model_if([id](const CameraModelInfo& model) { return model.id == id; });
}

const CameraModelInfo* find_camera_model(std::string_view name) {
  return find_camera_model_if([name](const CameraModelInfo& model) { return model.name == name; });
}

const CameraModelInfo& writable_camera_model(const ColmapCamera& camera, const fs::path& target) {
  const CameraModelInfo* model = find_camera_model(camera.model);
  if (!model)
    fail_file(target, fmt::format("camera {}: unknown model '{}'", camera.id, camera.model));
  if (camera.params.size() != model->num_params)
    fail_file(target, fmt::format("camera {}: model {} takes {} parameters, got {}", camera.id,
                                  camera.model, model->num_params, camera.params.size()));
  return *model;
}

const char* image_name_problem(std::string_view name) {
  if (name.empty()) return "is empty";
  for (char c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "contains a control character";
  if (name.front() == ' ' || name.back() == ' ') return "starts or ends with a space";
  return nullptr;
}

const std::string& writable_image_name(const ColmapImage& image, const fs::path& target) {
  if (const char* problem = image_name_problem(image.name))
    fail_file(target, fmt::format("image {}: name {}", image.id, problem));
  return image.name;
}

}  // namespace iesrgs::colmap_codec
