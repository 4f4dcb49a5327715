#pragma once
// The JSON records (stage.json, external.json) each cached stage keeps beside its outputs, and a
// run's results.json.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/scene.hpp"

namespace iesrgs::pipeline {

// The record's JSON object; an empty object when the file is missing or damaged, which only costs
// recomputing the stage.
nlohmann::json read_stage_record(const std::filesystem::path& path);

// One digest of a split's cameras (name, pinhole, distortion, pose) and of the content of their
// stored images, for the records of the stages that learn from or are scored against them.
std::string split_digest(const Scene& scene, Split split);

}  // namespace iesrgs::pipeline
