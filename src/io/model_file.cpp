#include "io/model_file.hpp"

#include "core/paths.hpp"
#include "io/splat_file.hpp"
#include "io/spz_file.hpp"

namespace iesrgs {

bool is_model_file(const std::filesystem::path& path) {
  const std::string extension = lowercase_extension(path);
  return extension == ".ply" || extension == ".spz" || extension == ".splat";
}

SplatCloud read_model(const std::filesystem::path& path) {
  const std::string extension = lowercase_extension(path);
  if (extension == ".spz") return read_spz(path);
  if (extension == ".splat") return read_splat(path);
  return read_ply(path);
}

}  // namespace iesrgs
