#pragma once
// Which files `iesrgs depth` reads and writes: one image or a folder of them in, per image a raw
// float32 map (.npy) and a false-color preview (PNG) out.
#include <torch/torch.h>

#include <filesystem>
#include <vector>

namespace iesrgs::priors::depth {

struct DepthJob {
  std::filesystem::path image;    // PNG or JPEG
  std::filesystem::path npy;      // raw (H, W) predictions
  std::filesystem::path preview;  // depth_preview of them
};

// The job writing `npy` and "<npy stem>_preview.png" beside it for `image`.
DepthJob depth_job(const std::filesystem::path& image, std::filesystem::path npy);

// plan_image_jobs with .npy results, each with "<npy stem>_preview.png" beside it. Throws Error
// naming the path as plan_image_jobs and refuse_overwrites do.
std::vector<DepthJob> plan_depth_jobs(const std::filesystem::path& in,
                                      const std::filesystem::path& out);

// Writes `depth` (H, W) to job.npy as float32 and its preview to job.preview, each atomically.
void write_depth_outputs(const torch::Tensor& depth, const DepthJob& job);

}  // namespace iesrgs::priors::depth
