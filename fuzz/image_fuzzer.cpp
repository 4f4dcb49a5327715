// Any byte string, as a file, must either read as an image of the size its header gives or throw
// iesrgs::Error. The readers take paths: the input is written to a file of this process's own.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "io/image.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("iesrgs-image-fuzz-" + std::to_string(::getpid()));
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
  try {
    const iesrgs::ImageHeader header = iesrgs::read_image_header(path);
    if (header.width <= 0 || header.height <= 0) std::abort();
    // The header's channels are the file's: a gray PNG with tRNS decodes with alpha, as two.
    const iesrgs::Image8 image = iesrgs::read_image8(path);
    if (image.width != header.width || image.height != header.height || image.channels < 1 ||
        image.channels > 4 ||
        image.data.size() != size_t(image.width) * size_t(image.height) * size_t(image.channels))
      std::abort();
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
