#pragma once
// Which files a command over "an image or a folder of images" (upscale, depth) reads and writes.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/folder_lock.hpp"

namespace iesrgs {

struct ImageJob {
  std::filesystem::path input;  // PNG or JPEG
  // The planned result first; a command may add files it writes beside it.
  std::vector<std::filesystem::path> outputs;
};

// `input` an image: one job writing `output`, which must end in `extension` unless it is an
// existing folder, where the result is <output>/<input stem><extension>. `input` a folder: one
// job per PNG or JPEG directly inside it, in name order, writing <output>/<stem><extension>.
// `command` names the command in messages. Throws Error naming the path when `input` is missing
// or holds no image, or when `output` cannot take the results.
std::vector<ImageJob> plan_image_jobs(const std::filesystem::path& input,
                                      const std::filesystem::path& output,
                                      const std::string& extension, const std::string& command);

// Throws Error naming the first output that another output, or an input, already names: two
// images sharing a stem (a.png, a.jpg), or results written into the input folder, would
// otherwise overwrite results or inputs without a word.
void refuse_overwrites(const std::vector<ImageJob>& jobs);

// Holds `output` against other writers while the jobs run (FolderLock) when `input` is a folder,
// whose results fill it, so that two commands never mix their results there; null for an image.
std::unique_ptr<FolderLock> lock_results_folder(const std::filesystem::path& input,
                                                const std::filesystem::path& output);

}  // namespace iesrgs
