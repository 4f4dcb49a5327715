#include "pipeline/stage_record.hpp"

#include "io/atomic_file.hpp"
#include "io/file_digest.hpp"

namespace iesrgs::pipeline {

nlohmann::json read_stage_record(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) return nlohmann::json::object();
  nlohmann::json record = nlohmann::json::parse(read_file(path), nullptr, false);
  return record.is_object() ? record : nlohmann::json::object();
}

std::string split_images_digest(const Scene& scene, Split split) {
  std::vector<std::filesystem::path> paths;
  for (const Camera* camera : scene.split(split)) paths.push_back(camera->image_path);
  return files_digest(paths);
}

}  // namespace iesrgs::pipeline
