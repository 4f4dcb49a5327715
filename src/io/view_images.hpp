#pragma once
// Lazy, bounded-memory access to a scene's images at the cameras' resolution. Nothing is decoded
// until asked for, and at most `cache_bytes` of decoded images stay in memory (least recently
// used first out), so a capture of thousands of images never has to fit in RAM at once.
#include <atomic>
#include <cstddef>
#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "io/image.hpp"
#include "io/scene.hpp"

namespace iesrgs {

struct ViewImageOptions {
  size_t cache_bytes = size_t(2) << 30;  // decoded float images kept in memory
  // Where undistorted images are cached once (the scene folder may be read-only).
  std::filesystem::path undistort_cache_dir = default_cache_dir() / "undistorted";

  // $IESRGS_CACHE_DIR, else $XDG_CACHE_HOME/iesrgs, else ~/.cache/iesrgs, else a temp folder.
  static std::filesystem::path default_cache_dir();
};

class ViewImages {
 public:
  explicit ViewImages(const Scene& scene, ViewImageOptions options = {});

  // RGB in [0, 1] at camera.intrinsics' size, alpha composited over the scene background.
  // Throws Error naming the file when it is missing, corrupt or of an unexpected size.
  std::shared_ptr<const Image> rgb(const Camera& camera);

  // The 8-bit image as it reaches the model, before compositing (RGB or RGBA).
  Image8 read8(const Camera& camera) const;

  // file_digest of the file the camera's image is read from: the pre-downscaled copy when there
  // is one, else the stored image. Taken once per file in this object's lifetime (one run), so
  // that every cache key of a run hashes each image once.
  std::string source_digest(const Camera& camera) const;

  const Scene& scene() const { return scene_; }

 private:
  std::filesystem::path source_path(const Camera& camera) const;
  Image8 read_source(const Camera& camera, Intrinsics& source_intrinsics) const;
  Image8 undistorted(const Camera& camera, const Image8& source,
                     const Intrinsics& source_intrinsics) const;

  const Scene& scene_;
  ViewImageOptions options_;
  std::mutex mutex_;
  std::list<std::string> lru_;  // most recent first
  std::unordered_map<std::string,
                     std::pair<std::shared_ptr<const Image>, std::list<std::string>::iterator>>
      cache_;
  size_t cached_bytes_ = 0;
  mutable std::mutex digest_mutex_;
  mutable std::unordered_map<std::string, std::string> digests_;  // by source path
  mutable std::atomic<bool> cache_failed_{false};  // said once: the cause is every image's
  mutable std::atomic<bool> copy_missing_{false};  // a copy folder lacking images, said once
};

}  // namespace iesrgs
