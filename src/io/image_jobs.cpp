#include "io/image_jobs.hpp"

#include <fmt/format.h>

#include <map>

#include "core/error.hpp"
#include "core/paths.hpp"
#include "io/image.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

fs::path result_in(const fs::path& folder, const fs::path& image, const std::string& extension) {
  return folder / image.stem().concat(extension);
}

}  // namespace

std::vector<ImageJob> plan_image_jobs(const fs::path& input, const fs::path& output,
                                      const std::string& extension, const std::string& command) {
  if (fs::is_directory(input)) {
    if (fs::exists(output) && !fs::is_directory(output))
      fail_file(output, "is a file, but the input is a folder");
    std::vector<ImageJob> jobs;
    for (const fs::path& image : image_files_in(input))
      jobs.push_back({image, {result_in(output, image, extension)}});
    return jobs;
  }
  if (!fs::exists(input)) fail_file(input, "no such image or folder");
  if (fs::is_directory(output)) return {{input, {result_in(output, input, extension)}}};
  if (lowercase_extension(output) != extension)
    fail_file(output, fmt::format("{} writes {} files: name the output {}, or give an existing "
                                  "folder",
                                  command, extension, extension));
  return {{input, {output}}};
}

void refuse_overwrites(const std::vector<ImageJob>& jobs) {
  std::map<fs::path, fs::path> inputs, written_for;
  for (const ImageJob& job : jobs) inputs.emplace(resolved_path(job.input), job.input);
  for (const ImageJob& job : jobs)
    for (const fs::path& output : job.outputs) {
      const fs::path file = resolved_path(output);
      if (const auto input = inputs.find(file); input != inputs.end())
        fail_file(output, "is an input image; write the results elsewhere");
      if (const auto [earlier, added] = written_for.emplace(file, job.input); !added)
        fail_file(output, fmt::format("would be written twice, for {} and for {}; rename one",
                                      earlier->second.string(), job.input.string()));
    }
}

std::unique_ptr<FolderLock> lock_results_folder(const fs::path& input, const fs::path& output) {
  if (!fs::is_directory(input)) return nullptr;
  return std::make_unique<FolderLock>(output);
}

}  // namespace iesrgs
