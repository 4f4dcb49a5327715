#include "priors/depth/depth_files.hpp"

#include <set>
#include <string>

#include "core/error.hpp"
#include "io/image.hpp"
#include "io/npy.hpp"
#include "priors/depth/depth_preview.hpp"

namespace iesrgs::priors::depth {

namespace {

namespace fs = std::filesystem;

// Two images with one stem (a.png, a.jpg), or an output folder that is the input one, would
// otherwise overwrite results or inputs without a word.
void check_names_unique(const std::vector<DepthJob>& jobs) {
  std::set<fs::path> taken;
  for (const DepthJob& job : jobs) taken.insert(fs::weakly_canonical(job.image));
  for (const DepthJob& job : jobs)
    for (const fs::path& output : {job.npy, job.preview})
      if (!taken.insert(fs::weakly_canonical(output)).second)
        fail_file(output, "would be written twice or overwrite an input image");
}

}  // namespace

DepthJob depth_job(const fs::path& image, fs::path npy) {
  fs::path preview = npy;
  preview.replace_filename(npy.stem().string() + "_preview.png");
  return {image, std::move(npy), std::move(preview)};
}

std::vector<DepthJob> plan_depth_jobs(const fs::path& in, const fs::path& out) {
  std::vector<DepthJob> jobs;
  if (fs::is_directory(in)) {
    for (const fs::path& image : image_files_in(in)) {
      jobs.push_back(depth_job(image, out / image.filename().replace_extension(".npy")));
    }
  } else {
    if (!fs::exists(in)) fail_file(in, "no such image or folder");
    if (out.extension() != ".npy") fail_file(out, "the output of a single image must end in .npy");
    jobs.push_back(depth_job(in, out));
  }
  check_names_unique(jobs);
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
