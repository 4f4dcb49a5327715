// COLMAP's binary model files: little-endian, uint64 record counts, null-terminated names.
#include <cstring>
#include <type_traits>
#include <utility>

#include "core/error.hpp"
#include "io/colmap_codec.hpp"

namespace iesrgs::colmap_codec {

namespace fs = std::filesystem;

namespace {

// Smallest possible size of each record, to reject a corrupt count before allocating for it.
constexpr size_t kMinCameraBytes = 4 + 4 + 8 + 8;         // id, model, width, height
constexpr size_t kMinImageBytes = 4 + 7 * 8 + 4 + 1 + 8;  // ..., empty name, count
constexpr size_t kObservationBytes = 2 * 8 + 8;           // x, y, point3D id
constexpr size_t kMinPointBytes = 8 + 3 * 8 + 3 + 8 + 8;  // ..., track length
constexpr size_t kTrackElementBytes = 4 + 4;              // image id, point2D index

class BinaryReader {
 public:
  BinaryReader(std::string_view bytes, const fs::path& source) : bytes_(bytes), source_(source) {}

  template <typename T>
  T read(const char* what) {
    static_assert(std::is_integral_v<T> && sizeof(T) <= 8);
    require(sizeof(T), what);
    uint64_t value = 0;
    for (size_t i = 0; i < sizeof(T); ++i)
      value |= uint64_t(static_cast<uint8_t>(bytes_[pos_ + i])) << (8 * i);
    pos_ += sizeof(T);
    return static_cast<T>(value);
  }

  double read_finite(const char* what) {
    const uint64_t bits = read<uint64_t>(what);
    double value;
    std::memcpy(&value, &bits, sizeof value);
    if (const std::string problem = number_problem(value, what); !problem.empty()) fail(problem);
    return value;
  }

  // A record count, refused when even the smallest records could not fit in the bytes left.
  uint64_t read_count(const char* what, size_t min_record_bytes) {
    const uint64_t count = read<uint64_t>(what);
    if (count > remaining() / min_record_bytes)
      fail(fmt::format("{} {} cannot fit in the {} bytes left, the file is corrupt or truncated",
                       what, count, remaining()));
    return count;
  }

  std::string read_name(const char* what) {
    const size_t end = bytes_.find('\0', pos_);
    if (end == std::string_view::npos) fail(fmt::format("truncated inside {}", what));
    std::string name(bytes_.substr(pos_, end - pos_));
    if (const char* problem = image_name_problem(name)) fail(fmt::format("{} {}", what, problem));
    pos_ = end + 1;
    return name;
  }

  void expect_end() const {
    if (remaining() != 0)
      fail(fmt::format("{} unexpected bytes after the last record", remaining()));
  }

  [[noreturn]] void fail(const std::string& problem) const {
    fail_file(source_, fmt::format("{} (at byte {})", problem, pos_));
  }

 private:
  size_t remaining() const { return bytes_.size() - pos_; }
  void require(size_t size, const char* what) const {
    if (remaining() < size) fail(fmt::format("truncated while reading {}", what));
  }

  std::string_view bytes_;
  const fs::path& source_;
  size_t pos_ = 0;
};

class BinaryWriter {
 public:
  template <typename T>
  void put(T value) {
    static_assert(std::is_integral_v<T>);
    const auto bits = static_cast<std::make_unsigned_t<T>>(value);
    for (size_t i = 0; i < sizeof(T); ++i) bytes_.push_back(static_cast<char>(bits >> (8 * i)));
  }
  void put(double value) {
    uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    put(bits);
  }
  void put_name(const std::string& name) { bytes_.append(name.c_str(), name.size() + 1); }

  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

ColmapCamera read_camera(BinaryReader& in) {
  ColmapCamera camera;
  camera.id = in.read<uint32_t>("camera id");
  const int model_id = in.read<int32_t>("camera model id");
  const CameraModelInfo* model = find_camera_model(model_id);
  if (!model) in.fail(fmt::format("camera {} has unknown model id {}", camera.id, model_id));
  camera.model = model->name;
  camera.width = in.read<uint64_t>("camera width");
  camera.height = in.read<uint64_t>("camera height");
  for (size_t i = 0; i < model->num_params; ++i)
    camera.params.push_back(in.read_finite("camera parameter"));
  return camera;
}

ColmapObservation read_observation(BinaryReader& in) {
  ColmapObservation observation;
  observation.x = in.read_finite("2D point x");
  observation.y = in.read_finite("2D point y");
  observation.point3d_id = in.read<int64_t>("2D point's 3D point id");
  if (observation.point3d_id < -1)
    in.fail(fmt::format("3D point id {} is negative", observation.point3d_id));
  return observation;
}

ColmapImage read_image(BinaryReader& in) {
  ColmapImage image;
  image.id = in.read<uint32_t>("image id");
  for (double* value : {&image.qw, &image.qx, &image.qy, &image.qz})
    *value = in.read_finite("image rotation");
  for (double* value : {&image.tx, &image.ty, &image.tz})
    *value = in.read_finite("image translation");
  image.camera_id = in.read<uint32_t>("image camera id");
  image.name = in.read_name("image name");
  const uint64_t count = in.read_count("2D point count", kObservationBytes);
  image.observations.reserve(count);
  for (uint64_t i = 0; i < count; ++i) image.observations.push_back(read_observation(in));
  return image;
}

ColmapPoint read_point(BinaryReader& in) {
  ColmapPoint point;
  point.id = in.read<uint64_t>("3D point id");
  for (double* value : {&point.x, &point.y, &point.z}) *value = in.read_finite("3D point position");
  for (uint8_t* value : {&point.r, &point.g, &point.b}) *value = in.read<uint8_t>("3D point color");
  point.error = in.read_finite("3D point error");
  const uint64_t length = in.read_count("track length", kTrackElementBytes);
  point.track.resize(length);
  for (ColmapTrackElement& element : point.track) {
    element.image_id = in.read<uint32_t>("track image id");
    element.point2d_index = in.read<uint32_t>("track 2D point index");
  }
  return point;
}

}  // namespace

Cameras decode_cameras_binary(std::string_view bytes, const fs::path& source) {
  BinaryReader in(bytes, source);
  Cameras cameras;
  const uint64_t count = in.read_count("camera count", kMinCameraBytes);
  for (uint64_t i = 0; i < count; ++i) insert_unique(cameras, read_camera(in), "camera", in);
  in.expect_end();
  return cameras;
}

Images decode_images_binary(std::string_view bytes, const fs::path& source) {
  BinaryReader in(bytes, source);
  Images images;
  const uint64_t count = in.read_count("image count", kMinImageBytes);
  for (uint64_t i = 0; i < count; ++i) insert_unique(images, read_image(in), "image", in);
  in.expect_end();
  return images;
}

Points decode_points_binary(std::string_view bytes, const fs::path& source) {
  BinaryReader in(bytes, source);
  Points points(in.read_count("3D point count", kMinPointBytes));
  for (ColmapPoint& point : points) point = read_point(in);
  in.expect_end();
  return points;
}

std::string encode_cameras_binary(const Cameras& cameras, const fs::path& target) {
  BinaryWriter out;
  out.put(uint64_t(cameras.size()));
  for (const auto& [id, camera] : cameras) {
    out.put(camera.id);
    out.put(int32_t(writable_camera_model(camera, target).id));
    out.put(camera.width);
    out.put(camera.height);
    for (double param : camera.params) out.put(param);
  }
  return out.take();
}

std::string encode_images_binary(const Images& images, const fs::path& target) {
  BinaryWriter out;
  out.put(uint64_t(images.size()));
  for (const auto& [id, image] : images) {
    out.put(image.id);
    for (double value : {image.qw, image.qx, image.qy, image.qz, image.tx, image.ty, image.tz})
      out.put(value);
    out.put(image.camera_id);
    out.put_name(writable_image_name(image, target));
    out.put(uint64_t(image.observations.size()));
    for (const ColmapObservation& observation : image.observations) {
      out.put(observation.x);
      out.put(observation.y);
      out.put(observation.point3d_id);
    }
  }
  return out.take();
}

std::string encode_points_binary(const Points& points) {
  BinaryWriter out;
  out.put(uint64_t(points.size()));
  for (const ColmapPoint& point : points) {
    out.put(point.id);
    for (double value : {point.x, point.y, point.z}) out.put(value);
    for (uint8_t value : {point.r, point.g, point.b}) out.put(value);
    out.put(point.error);
    out.put(uint64_t(point.track.size()));
    for (const ColmapTrackElement& element : point.track) {
      out.put(element.image_id);
      out.put(element.point2d_index);
    }
  }
  return out.take();
}

}  // namespace iesrgs::colmap_codec
