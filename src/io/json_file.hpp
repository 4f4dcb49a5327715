#pragma once
// JSON documents read from files, with errors that name the file and where the text goes wrong.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace iesrgs {

// `text` (the contents of json_path) parsed; malformed JSON fails naming the file, the byte and
// the problem.
nlohmann::json parse_json(const std::string& text, const std::filesystem::path& json_path);

// The file at `path` parsed.
nlohmann::json read_json_file(const std::filesystem::path& path);

}  // namespace iesrgs
