#include "core/error.hpp"

namespace iesrgs {

void fail_file(const std::filesystem::path& path, const std::string& problem) {
  throw Error(path.string() + ": " + problem);
}

}  // namespace iesrgs
