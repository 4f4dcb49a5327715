#pragma once
// The JSON records (stage.json, external.json) each cached stage keeps beside its outputs, and a
// run's results.json.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.hpp"
#include "io/scene.hpp"
#include "io/view_images.hpp"

namespace iesrgs::pipeline {

// The record's JSON object; an empty object when the file is missing or damaged, which only costs
// recomputing the stage.
nlohmann::json read_stage_record(const std::filesystem::path& path);

// <dir>/stage.json of any stage: written when it starts and on completion, with its parameters
// and running time. Recorded: started with these parameters, finished or not.
bool stage_recorded(const std::filesystem::path& dir, const nlohmann::json& params);
bool stage_finished(const std::filesystem::path& dir, const nlohmann::json& params);
double stage_seconds(const std::filesystem::path& dir);
void record_stage(const std::filesystem::path& dir, const nlohmann::json& params, bool finished,
                  double seconds);

// read(path) for an output a cached stage wrote (outputs are written atomically, so damage comes
// from outside); its Error then also says how to have the file made again.
template <typename Read>
auto read_cached_output(const std::filesystem::path& path, Read read) -> decltype(read(path)) {
  try {
    return read(path);
  } catch (const Error& e) {
    throw Error(
        std::string(e.what()) +
        "; it is a cached output of an earlier run: delete it and run again to recompute it");
  }
}

// Whether a cached view's image (and depth map, unless `depth` is empty) decode at width x height.
// Files damaged or replaced since they were written are made again rather than failing a later
// stage.
bool cached_view_intact(const std::filesystem::path& image, const std::filesystem::path& depth,
                        int width, int height);

// One digest of the cameras of a split of `images`' scene (name, pinhole, distortion, pose), of
// the content of the image files `images` reads for them and of the background they are
// composited over, for the records of the stages that learn from or are scored against them. Not
// their folder: a moved or copied dataset keeps its caches.
std::string split_digest(const ViewImages& images, Split split);

// Digest of the SfM points a model starts from (empty for synthetic scenes).
std::string points_digest(const PointCloud& points);

}  // namespace iesrgs::pipeline
