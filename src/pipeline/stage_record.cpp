#include "pipeline/stage_record.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <string>
#include <vector>

#include "core/log_once.hpp"
#include "io/atomic_file.hpp"
#include "io/file_digest.hpp"
#include "io/image.hpp"
#include "io/npy.hpp"

namespace iesrgs::pipeline {

nlohmann::json read_stage_record(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) return nlohmann::json::object();
  nlohmann::json record = nlohmann::json::parse(read_file(path), nullptr, false);
  return record.is_object() ? record : nlohmann::json::object();
}

namespace {

// A record whose fields have other types than record_stage writes was damaged from outside; it
// counts as none, as an unreadable one does, and the stage trains again.
nlohmann::json stage_json(const std::filesystem::path& dir) {
  const nlohmann::json record = read_stage_record(dir / "stage.json");
  const bool typed = record.value("finished", nlohmann::json(false)).is_boolean() &&
                     record.value("seconds", nlohmann::json(0.0)).is_number();
  return typed ? record : nlohmann::json::object();
}

// Whether the record is of these parameters. When it is of others, says which at debug level
// (iesrgs -v), once for a record however often it is checked: why a stage is made again is
// otherwise a guess.
bool params_match(const std::filesystem::path& dir, const nlohmann::json& record,
                  const nlohmann::json& params) {
  const nlohmann::json recorded = record.value("params", nlohmann::json());
  if (recorded == params) return true;
  if (!recorded.is_null() && spdlog::should_log(spdlog::level::debug)) {
    std::vector<std::string> changed;
    for (const nlohmann::json& operation : nlohmann::json::diff(recorded, params))
      changed.push_back(operation.value("path", ""));
    const std::string message =
        fmt::format("{}: recorded with other parameters ({})", (dir / "stage.json").string(),
                    fmt::join(changed, ", "));
    debug_once(message);
  }
  return false;
}

}  // namespace

bool stage_recorded(const std::filesystem::path& dir, const nlohmann::json& params) {
  return params_match(dir, stage_json(dir), params);
}

bool stage_finished(const std::filesystem::path& dir, const nlohmann::json& params) {
  const nlohmann::json record = stage_json(dir);
  return params_match(dir, record, params) && record.value("finished", false);
}

double stage_seconds(const std::filesystem::path& dir) {
  return stage_json(dir).value("seconds", 0.0);
}

void record_stage(const std::filesystem::path& dir, const nlohmann::json& params, bool finished,
                  double seconds) {
  const nlohmann::json record = {{"params", params}, {"finished", finished}, {"seconds", seconds}};
  write_file_atomically(dir / "stage.json", record.dump(2) + "\n");
}

bool cached_view_intact(const std::filesystem::path& image, const std::filesystem::path& depth,
                        int width, int height) {
  try {
    const Image8 decoded = read_image8(image);
    if (decoded.width != width || decoded.height != height) return false;
    return depth.empty() ||
           read_npy(depth).shape == std::vector<size_t>{size_t(height), size_t(width)};
  } catch (const Error&) {
    return false;
  }
}

std::string split_digest(const ViewImages& images, Split split) {
  const Scene& scene = images.scene();
  std::string key = fmt::format("background {};\n", fmt::join(scene.background, " "));
  // The lens as it was keyed before FULL_OPENCV's terms were read, and those only when used,
  // so that run folders of OPENCV captures keep their stages.
  for (const Camera* camera : scene.split(split)) {
    const Intrinsics& k = camera->intrinsics;
    const Distortion& d = camera->distortion;
    key +=
        fmt::format("{} {} {}x{} {} {} {} {} | {} {} {} {}{} | {} | {} {} {};\n", camera->name,
                    images.source_digest(*camera), k.width, k.height, k.fx, k.fy, k.cx, k.cy, d.k1,
                    d.k2, d.p1, d.p2, d.terms_beyond_opencv(), fmt::join(camera->rotation.m, " "),
                    camera->translation.x, camera->translation.y, camera->translation.z);
  }
  return bytes_digest(key);
}

std::string points_digest(const PointCloud& points) {
  const auto bytes = [](const auto& values) {
    return std::string_view(reinterpret_cast<const char*>(values.data()),
                            values.size() * sizeof(values[0]));
  };
  return bytes_digest(fmt::format("{} {}", bytes_digest(bytes(points.positions)),
                                  bytes_digest(bytes(points.colors))));
}

}  // namespace iesrgs::pipeline
