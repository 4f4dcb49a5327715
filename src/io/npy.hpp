#pragma once
// NumPy .npy files (format 1.0, little-endian float32), for depth maps and other raw arrays.
#include <filesystem>
#include <vector>

namespace iesrgs {

struct NpyArray {
  std::vector<size_t> shape;
  std::vector<float> data;
};

// Written atomically (temporary name, then rename).
void write_npy(const std::filesystem::path& path, const std::vector<float>& data,
               const std::vector<size_t>& shape);
// Reads '<f4' C-order arrays; throws Error naming the file for anything else.
NpyArray read_npy(const std::filesystem::path& path);

}  // namespace iesrgs
