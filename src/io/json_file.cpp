#include "io/json_file.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs {

namespace {

// what() starts with an id such as "[json.exception.parse_error.101] ": what follows it.
std::string without_id(const nlohmann::json::exception& e) {
  const std::string detail = e.what();
  const size_t id_end = detail.find("] ");
  return detail.substr(id_end == std::string::npos ? 0 : id_end + 2);
}

}  // namespace

nlohmann::json parse_json(const std::string& text, const std::filesystem::path& json_path) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    fail_file(json_path, fmt::format("malformed JSON at byte {} ({})", e.byte, without_id(e)));
  } catch (const nlohmann::json::exception& e) {  // e.g. a number too large for a double
    fail_file(json_path, fmt::format("invalid JSON ({})", without_id(e)));
  }
}

nlohmann::json read_json_file(const std::filesystem::path& path) {
  return parse_json(read_file(path), path);
}

}  // namespace iesrgs
