#include "io/view_images.hpp"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <iterator>

#include "core/error.hpp"
#include "core/paths.hpp"
#include "io/file_digest.hpp"
#include "io/resize.hpp"
#include "io/undistort.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

std::string describe(const Intrinsics& k) {
  return fmt::format("{}x{}", k.width, k.height);
}

// Identifies an undistorted result: the source's content and every parameter used.
std::string undistort_key(const std::string& source_digest, const Intrinsics& k,
                          const Distortion& d, const Intrinsics& pinhole) {
  return bytes_digest(
      fmt::format("{}|{}x{}|{:.9g},{:.9g},{:.9g},{:.9g}|{:.9g},{:.9g},{:.9g},{:.9g}", source_digest,
                  k.width, k.height, k.fx, k.fy, k.cx, k.cy, d.k1, d.k2, d.p1, d.p2) +
      d.terms_beyond_opencv() +
      fmt::format("|pinhole {:.9g},{:.9g},{:.9g},{:.9g}", pinhole.fx, pinhole.fy, pinhole.cx,
                  pinhole.cy));
}

// `k`, of the stored image, for a copy of it `width` x `height` pixels.
Intrinsics for_copy(const Intrinsics& k, int width, int height) {
  Intrinsics copy = k.scaled(static_cast<double>(width) / k.width);
  copy.width = width;
  copy.height = height;
  return copy;
}

// Where a camera's size came from, for the error of an image that does not match it. A
// NeRF-Synthetic split has one camera angle, and its size is that of the split's first image,
// which may be the odd one out.
std::string size_origin(const Scene& scene, const Camera& camera) {
  if (scene.format == "blender")
    for (const Camera& first : scene.cameras)
      if (first.split == camera.split)
        return fmt::format("(the size of {}, the first image of its split: all must match)",
                           first.image_path.string());
  return "like the scene's cameras";
}

}  // namespace

fs::path ViewImageOptions::default_cache_dir() {
  if (auto dir = env_path("IESRGS_CACHE_DIR")) return *dir;
  return user_cache_dir("iesrgs").value_or(fs::temp_directory_path() / "iesrgs-cache");
}

ViewImages::ViewImages(const Scene& scene, ViewImageOptions options)
    : scene_(scene), options_(std::move(options)) {}

Image8 ViewImages::read_source(const Camera& camera, Intrinsics& source_intrinsics) const {
  if (const fs::path copy = source_path(camera); copy != camera.image_path) {
    Image8 image = read_image8(copy);
    const Intrinsics expected = camera.stored.scaled(1.0 / scene_.downscale);
    if (std::abs(image.width - expected.width) > 1 || std::abs(image.height - expected.height) > 1)
      fail_file(copy, fmt::format("image is {}x{}, expected about {} (1/{} of {})", image.width,
                                  image.height, describe(expected), scene_.downscale,
                                  describe(camera.stored)));
    source_intrinsics = for_copy(camera.stored, image.width, image.height);
    return image;
  }
  Image8 image = read_image8(camera.image_path);
  if (image.width != camera.stored.width || image.height != camera.stored.height)
    fail_file(camera.image_path,
              fmt::format("image is {}x{}, expected {} {}", image.width, image.height,
                          describe(camera.stored), size_origin(scene_, camera)));
  source_intrinsics = camera.stored;
  return image;
}

Image8 ViewImages::undistorted(const Camera& camera, const Image8& source,
                               const Intrinsics& source_intrinsics) const {
  const Intrinsics pinhole = for_copy(camera.pinhole, source.width, source.height);
  const fs::path cached =
      options_.undistort_cache_dir /
      (undistort_key(source_digest(camera), source_intrinsics, camera.distortion, pinhole) +
       ".png");
  std::error_code ec;
  if (fs::is_regular_file(cached, ec)) {
    try {
      Image8 image = read_image8(cached);
      if (image.width == source.width && image.height == source.height &&
          image.channels == source.channels)
        return image;
    } catch (const Error& e) {
      spdlog::warn("ignoring unreadable undistortion cache entry: {}", e.what());
    }
  }
  Image8 image = undistort_image(source, source_intrinsics, camera.distortion, pinhole);
  try {
    write_png(cached, image);
  } catch (const Error& e) {
    if (!cache_failed_.exchange(true))
      spdlog::warn(
          "cannot cache undistorted images ({}); continuing without the cache, so each run "
          "undistorts them again (IESRGS_CACHE_DIR sets where it is)",
          e.what());
  }
  return image;
}

fs::path ViewImages::source_path(const Camera& camera) const {
  const DownscaledCopy copy = downscaled_copy(scene_.root, camera.image_path, scene_.downscale);
  std::error_code ec;
  if (copy.file.empty()) return camera.image_path;
  if (fs::is_regular_file(copy.file, ec)) return copy.file;
  // A copy folder that lacks some images mixes two resizes of one scene: said, once.
  if (fs::is_directory(copy.folder, ec) && !copy_missing_.exchange(true))
    spdlog::warn(
        "{}: holds no copy of {} (the first of the scene's images it lacks); such views "
        "are resized from the stored images instead",
        copy.folder.string(), camera.image_path.filename().string());
  return camera.image_path;
}

std::string ViewImages::source_digest(const Camera& camera) const {
  const fs::path path = source_path(camera);
  {
    std::lock_guard<std::mutex> lock(digest_mutex_);
    if (auto it = digests_.find(path.string()); it != digests_.end()) return it->second;
  }
  std::string digest = file_digest(path);
  std::lock_guard<std::mutex> lock(digest_mutex_);
  return digests_.emplace(path.string(), std::move(digest)).first->second;
}

Image8 ViewImages::read8(const Camera& camera) const {
  Intrinsics source_intrinsics;
  Image8 image = read_source(camera, source_intrinsics);
  if (camera.distortion.any()) image = undistorted(camera, image, source_intrinsics);
  const Intrinsics& target = camera.intrinsics;
  if (image.width != target.width || image.height != target.height)
    image = resize_bicubic(image, target.width, target.height);
  return image;
}

std::shared_ptr<const Image> ViewImages::rgb(const Camera& camera) {
  const std::string key = camera.image_path.string();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto it = cache_.find(key); it != cache_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second.second);
      return it->second.first;
    }
  }
  auto image =
      std::make_shared<const Image>(composite_rgb(read8(camera), scene_.background.data()));
  const size_t bytes = image->data.size() * sizeof(float);
  std::lock_guard<std::mutex> lock(mutex_);
  if (bytes > options_.cache_bytes || cache_.count(key)) return image;
  while (cached_bytes_ + bytes > options_.cache_bytes && !lru_.empty()) {
    auto victim = cache_.find(lru_.back());
    cached_bytes_ -= victim->second.first->data.size() * sizeof(float);
    cache_.erase(victim);
    lru_.pop_back();
  }
  lru_.push_front(key);
  cache_.emplace(key, std::make_pair(image, lru_.begin()));
  cached_bytes_ += bytes;
  return image;
}

}  // namespace iesrgs
