#include "io/model_file.hpp"

#include "core/paths.hpp"
#include "io/spz_file.hpp"

namespace iesrgs {

bool is_model_file(const std::filesystem::path& path) {
  const std::string extension = lowercase_extension(path);
  return extension == ".ply" || extension == ".spz";
}

SplatCloud read_model(const std::filesystem::path& path) {
  return lowercase_extension(path) == ".spz" ? read_spz(path) : read_ply(path);
}

}  // namespace iesrgs
