// Any byte string, as a file, must either read as an array holding as many values as its shape
// counts or throw iesrgs::Error. read_npy takes a path: the input is written to a file of this
// process's own.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "io/npy.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("iesrgs-npy-fuzz-" + std::to_string(::getpid()));
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
  try {
    const iesrgs::NpyArray array = iesrgs::read_npy(path);
    size_t count = 1;
    for (size_t extent : array.shape) count *= extent;
    if (count != array.data.size()) std::abort();
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
