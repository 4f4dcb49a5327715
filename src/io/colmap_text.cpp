// COLMAP's text model files: '#' comment lines, one record per line, except images, which take
// two lines each (the second lists the 2D points and may be empty).
#include <charconv>
#include <iterator>

#include "core/error.hpp"
#include "io/colmap_codec.hpp"

namespace iesrgs::colmap_codec {

namespace fs = std::filesystem;

namespace {

bool is_blank(char c) {
  return c == ' ' || c == '\t';
}

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && (is_blank(text.front()) || text.front() == '\r')) text.remove_prefix(1);
  while (!text.empty() && (is_blank(text.back()) || text.back() == '\r')) text.remove_suffix(1);
  return text;
}

// A field as it may appear in a one-line message: short, with control characters replaced.
std::string printable(std::string_view field) {
  constexpr size_t kMaxShown = 32;
  std::string shown(field.substr(0, kMaxShown));
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  return field.size() > kMaxShown ? shown + "..." : shown;
}

// Walks a text file line by line and each line field by field; errors name the line.
class TextReader {
 public:
  TextReader(std::string_view text, const fs::path& source) : source_(source), rest_(text) {
    // Editors on Windows start UTF-8 files with a byte-order mark, invisible in any message.
    if (rest_.substr(0, 3) == "\xEF\xBB\xBF") rest_.remove_prefix(3);
  }

  // Moves to the next line holding data (not blank, not a comment); false at the end.
  bool next_data_line() {
    while (next_line())
      if (!line_.empty() && line_.front() != '#') return true;
    return false;
  }

  // Moves to the next line whatever it holds; false at the end (a final newline ends the last
  // line, it does not start an empty one).
  bool next_line() {
    if (rest_.empty()) return false;
    const size_t end = rest_.find('\n');
    line_ = trimmed(rest_.substr(0, end));
    rest_.remove_prefix(end == std::string_view::npos ? rest_.size() : end + 1);
    ++line_number_;
    return true;
  }

  bool at_line_end() const { return line_.empty(); }

  std::string_view field(const char* what) {
    // Stops at the first blank: a search for a tab alone ran to the end of the line for every
    // field, quadratic in the length of a long track.
    const size_t end = line_.find_first_of(" \t");
    const std::string_view token = line_.substr(0, end);
    if (token.empty()) fail(fmt::format("missing {}", what));
    line_ = trimmed(line_.substr(token.size()));
    return token;
  }

  template <typename T>
  T number(const char* what) {
    const std::string_view token = field(what);
    T value{};
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size())
      fail(fmt::format("{} '{}' is not a valid number", what, printable(token)));
    if constexpr (std::is_floating_point_v<T>)
      if (const std::string problem = number_problem(value, what); !problem.empty()) fail(problem);
    return value;
  }

  std::string_view rest_of_line() {
    const std::string_view rest = line_;
    line_ = {};
    return rest;
  }

  [[noreturn]] void fail(const std::string& problem) const {
    fail_file(source_, fmt::format("line {}: {}", line_number_, problem));
  }

 private:
  const fs::path& source_;
  std::string_view rest_;
  std::string_view line_;
  size_t line_number_ = 0;
};

ColmapCamera read_camera(TextReader& in) {
  ColmapCamera camera;
  camera.id = in.number<uint32_t>("CAMERA_ID");
  const std::string_view model_name = in.field("MODEL");
  const CameraModelInfo* model = find_camera_model(model_name);
  if (!model) in.fail(fmt::format("unknown camera model '{}'", printable(model_name)));
  camera.model = model->name;
  camera.width = in.number<uint64_t>("WIDTH");
  camera.height = in.number<uint64_t>("HEIGHT");
  while (!in.at_line_end()) camera.params.push_back(in.number<double>("camera parameter"));
  if (camera.params.size() != model->num_params)
    in.fail(fmt::format("camera {}: model {} takes {} parameters, found {}", camera.id, model->name,
                        model->num_params, camera.params.size()));
  return camera;
}

ColmapObservation read_observation(TextReader& in) {
  ColmapObservation observation;
  observation.x = in.number<double>("2D point X");
  observation.y = in.number<double>("2D point Y");
  observation.point3d_id = in.number<int64_t>("POINT3D_ID");
  if (observation.point3d_id < -1)
    in.fail(fmt::format("POINT3D_ID {} is negative", observation.point3d_id));
  return observation;
}

ColmapImage read_image(TextReader& in) {
  ColmapImage image;
  image.id = in.number<uint32_t>("IMAGE_ID");
  image.qw = in.number<double>("QW");
  image.qx = in.number<double>("QX");
  image.qy = in.number<double>("QY");
  image.qz = in.number<double>("QZ");
  image.tx = in.number<double>("TX");
  image.ty = in.number<double>("TY");
  image.tz = in.number<double>("TZ");
  image.camera_id = in.number<uint32_t>("CAMERA_ID");
  image.name = in.rest_of_line();
  if (const char* problem = image_name_problem(image.name))
    in.fail(fmt::format("image {}: NAME {}", image.id, problem));
  // A missing second line at the very end of the file is read as an image without 2D points.
  if (!in.next_line()) return image;
  try {
    while (!in.at_line_end()) image.observations.push_back(read_observation(in));
  } catch (const Error& e) {
    // A file that leaves the second lines out fails here, on the next image's pose.
    throw Error(std::string(e.what()) +
                " (each image takes two lines: its pose and name, then its 2D points as X Y "
                "POINT3D_ID, an empty line for none)");
  }
  return image;
}

ColmapPoint read_point(TextReader& in) {
  ColmapPoint point;
  point.id = in.number<uint64_t>("POINT3D_ID");
  point.x = in.number<double>("X");
  point.y = in.number<double>("Y");
  point.z = in.number<double>("Z");
  point.r = in.number<uint8_t>("R");
  point.g = in.number<uint8_t>("G");
  point.b = in.number<uint8_t>("B");
  point.error = in.number<double>("ERROR");
  while (!in.at_line_end()) {
    ColmapTrackElement element;
    element.image_id = in.number<uint32_t>("track IMAGE_ID");
    element.point2d_index = in.number<uint32_t>("track POINT2D_IDX");
    point.track.push_back(element);
  }
  return point;
}

double mean(size_t total, size_t count) {
  return count == 0 ? 0.0 : double(total) / count;
}

}  // namespace

Cameras decode_cameras_text(std::string_view text, const fs::path& source) {
  TextReader in(text, source);
  Cameras cameras;
  while (in.next_data_line()) insert_unique(cameras, read_camera(in), "camera", in);
  return cameras;
}

Images decode_images_text(std::string_view text, const fs::path& source) {
  TextReader in(text, source);
  Images images;
  while (in.next_data_line()) insert_unique(images, read_image(in), "image", in);
  return images;
}

Points decode_points_text(std::string_view text, const fs::path& source) {
  TextReader in(text, source);
  Points points;
  while (in.next_data_line()) points.push_back(read_point(in));
  return points;
}

std::string encode_cameras_text(const Cameras& cameras, const fs::path& target) {
  fmt::memory_buffer out;
  auto put = std::back_inserter(out);
  fmt::format_to(put,
                 "# Camera list with one line of data per camera:\n"
                 "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                 "# Number of cameras: {}\n",
                 cameras.size());
  for (const auto& [id, camera] : cameras) {
    fmt::format_to(put, "{} {} {} {}", camera.id, writable_camera_model(camera, target).name,
                   camera.width, camera.height);
    for (double param : camera.params) fmt::format_to(put, " {}", param);
    out.push_back('\n');
  }
  return fmt::to_string(out);
}

std::string encode_images_text(const Images& images, const fs::path& target) {
  size_t observations = 0;
  for (const auto& [id, image] : images) observations += image.observations.size();
  fmt::memory_buffer out;
  auto put = std::back_inserter(out);
  fmt::format_to(put,
                 "# Image list with two lines of data per image:\n"
                 "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
                 "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
                 "# Number of images: {}, mean observations per image: {}\n",
                 images.size(), mean(observations, images.size()));
  for (const auto& [id, image] : images) {
    fmt::format_to(put, "{} {} {} {} {} {} {} {} {} {}\n", image.id, image.qw, image.qx, image.qy,
                   image.qz, image.tx, image.ty, image.tz, image.camera_id,
                   writable_image_name(image, target));
    const char* separator = "";
    for (const ColmapObservation& observation : image.observations) {
      fmt::format_to(put, "{}{} {} {}", separator, observation.x, observation.y,
                     observation.point3d_id);
      separator = " ";
    }
    out.push_back('\n');
  }
  return fmt::to_string(out);
}

std::string encode_points_text(const Points& points) {
  size_t track_elements = 0;
  for (const ColmapPoint& point : points) track_elements += point.track.size();
  fmt::memory_buffer out;
  auto put = std::back_inserter(out);
  fmt::format_to(put,
                 "# 3D point list with one line of data per point:\n"
                 "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
                 "# Number of points: {}, mean track length: {}\n",
                 points.size(), mean(track_elements, points.size()));
  for (const ColmapPoint& point : points) {
    fmt::format_to(put, "{} {} {} {} {} {} {} {}", point.id, point.x, point.y, point.z, point.r,
                   point.g, point.b, point.error);
    for (const ColmapTrackElement& element : point.track)
      fmt::format_to(put, " {} {}", element.image_id, element.point2d_index);
    out.push_back('\n');
  }
  return fmt::to_string(out);
}

}  // namespace iesrgs::colmap_codec
