#include "pipeline/stage_record.hpp"

#include "io/atomic_file.hpp"

namespace iesrgs::pipeline {

nlohmann::json read_stage_record(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) return nlohmann::json::object();
  nlohmann::json record = nlohmann::json::parse(read_file(path), nullptr, false);
  return record.is_object() ? record : nlohmann::json::object();
}

}  // namespace iesrgs::pipeline
