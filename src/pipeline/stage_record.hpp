#pragma once
// The JSON records (stage.json, external.json) each cached stage keeps beside its outputs, and a
// run's results.json.
#include <filesystem>
#include <nlohmann/json.hpp>

namespace iesrgs::pipeline {

// The record's JSON object; an empty object when the file is missing or damaged, which only costs
// recomputing the stage.
nlohmann::json read_stage_record(const std::filesystem::path& path);

}  // namespace iesrgs::pipeline
