#include "priors/depth/depth_files.hpp"

#include <string>

#include "io/image.hpp"
#include "io/image_jobs.hpp"
#include "io/npy.hpp"
#include "priors/depth/depth_preview.hpp"

namespace iesrgs::priors::depth {

namespace fs = std::filesystem;

DepthJob depth_job(const fs::path& image, fs::path npy) {
  fs::path preview = npy;
  preview.replace_filename(npy.stem().string() + "_preview.png");
  return {image, std::move(npy), std::move(preview)};
}

std::vector<DepthJob> plan_depth_jobs(const fs::path& in, const fs::path& out) {
  std::vector<ImageJob> planned = plan_image_jobs(in, out, ".npy", "depth");
  std::vector<DepthJob> jobs;
  for (ImageJob& job : planned) {
    jobs.push_back(depth_job(job.input, job.outputs[0]));
    job.outputs.push_back(jobs.back().preview);
  }
  refuse_overwrites(planned);
  return jobs;
}

void write_depth_outputs(const torch::Tensor& depth, const DepthJob& job) {
  const torch::Tensor map = depth.detach().to(torch::kCPU, torch::kFloat32).contiguous();
  const Image8 preview = depth_preview(map);  // also rejects anything but an (H, W) map
  const float* values = map.data_ptr<float>();
  write_npy(job.npy, std::vector<float>(values, values + map.numel()),
            {size_t(map.size(0)), size_t(map.size(1))});
  write_png(job.preview, preview);
}

}  // namespace iesrgs::priors::depth
