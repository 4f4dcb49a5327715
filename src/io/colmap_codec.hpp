#pragma once
// Internal to the COLMAP model reader and writer: COLMAP's camera model table and one decoder /
// encoder per file and encoding. `source` / `target` only name the file in error messages.
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/math.hpp"
#include "io/colmap.hpp"

namespace iesrgs::colmap_codec {

struct CameraModelInfo {
  int id;
  std::string_view name;
  size_t num_params;
};

// Every model COLMAP defines, by id (binary files) or name (text files); nullptr when unknown.
const CameraModelInfo* find_camera_model(int id);
const CameraModelInfo* find_camera_model(std::string_view name);

// The model of a camera about to be written; throws Error naming `target` when it is unknown or
// the parameter count does not match it, since the file could not be read back.
const CameraModelInfo& writable_camera_model(const ColmapCamera& camera,
                                             const std::filesystem::path& target);

// Why `name` cannot be an image name, or nullptr when it can. Names must survive both encodings
// (null-terminated in binary, rest of a whitespace-trimmed line in text) and one-line messages.
const char* image_name_problem(std::string_view name);

// The name of an image about to be written; throws Error naming `target` when it is not valid.
const std::string& writable_image_name(const ColmapImage& image,
                                       const std::filesystem::path& target);

// Why a decoded number cannot be used, or an empty string. NaN and infinities are refused, and so
// is a value beyond the float range, since positions and intrinsics are used in single precision.
inline std::string number_problem(double value, const char* what) {
  if (!std::isfinite(value)) return fmt::format("{} is not finite", what);
  if (!fits_float(value))
    return fmt::format("{} {} is beyond the single-precision range", what, value);
  return {};
}

// Adds `record` under its id; `in` reports a repeated id (ids are unique within a file).
template <typename Record, typename Reader>
void insert_unique(std::map<uint32_t, Record>& records, Record record, const char* kind,
                   const Reader& in) {
  const uint32_t id = record.id;
  if (!records.emplace(id, std::move(record)).second)
    in.fail(fmt::format("{} id {} appears twice", kind, id));
}

using Cameras = std::map<uint32_t, ColmapCamera>;
using Images = std::map<uint32_t, ColmapImage>;
using Points = std::vector<ColmapPoint>;

Cameras decode_cameras_binary(std::string_view bytes, const std::filesystem::path& source);
Images decode_images_binary(std::string_view bytes, const std::filesystem::path& source);
Points decode_points_binary(std::string_view bytes, const std::filesystem::path& source);
Cameras decode_cameras_text(std::string_view text, const std::filesystem::path& source);
Images decode_images_text(std::string_view text, const std::filesystem::path& source);
Points decode_points_text(std::string_view text, const std::filesystem::path& source);

std::string encode_cameras_binary(const Cameras& cameras, const std::filesystem::path& target);
std::string encode_images_binary(const Images& images, const std::filesystem::path& target);
std::string encode_points_binary(const Points& points);
std::string encode_cameras_text(const Cameras& cameras, const std::filesystem::path& target);
std::string encode_images_text(const Images& images, const std::filesystem::path& target);
std::string encode_points_text(const Points& points);

}  // namespace iesrgs::colmap_codec
