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

// `in` an image file: one job writing `out` (which must end in .npy) and "<out stem>_preview.png"
// beside it. `in` a folder: one job per PNG or JPEG file directly inside it, by name, writing
// "<out>/<image stem>.npy" and "<out>/<image stem>_preview.png". Throws Error naming the path
// when `in` is missing or holds no image, when `out` lacks .npy, or when two outputs or an output
// and an input would share a name.
std::vector<DepthJob> plan_depth_jobs(const std::filesystem::path& in,
                                      const std::filesystem::path& out);

// Writes `depth` (H, W) to job.npy as float32 and its preview to job.preview, each atomically.
void write_depth_outputs(const torch::Tensor& depth, const DepthJob& job);

}  // namespace iesrgs::priors::depth
