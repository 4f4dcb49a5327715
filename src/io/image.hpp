#pragma once
// 8-bit and float images (interleaved HWC) with PNG / JPEG decoding and atomic PNG writing.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <utility>
#include <vector>

namespace iesrgs {

// Interleaved channels (HWC), row-major.
template <typename T>
struct ImageOf {
  int width = 0, height = 0, channels = 0;
  std::vector<T> data;

  ImageOf() = default;
  ImageOf(int w, int h, int c) : width(w), height(h), channels(c), data(size_t(w) * h * c, T{}) {}
  T& at(int x, int y, int c) { return data[(size_t(y) * width + x) * channels + c]; }
  T at(int x, int y, int c) const { return data[(size_t(y) * width + x) * channels + c]; }
  size_t pixels() const { return size_t(width) * height; }
};

using Image = ImageOf<float>;     // values in [0, 1] for color
using Image8 = ImageOf<uint8_t>;  // as stored in files

struct ImageHeader {
  int width = 0, height = 0;
};

// The PNG and JPEG files directly inside `folder`, in name order; throws Error naming the folder
// when it holds none.
std::vector<std::filesystem::path> image_files_in(const std::filesystem::path& folder);

// The first two of `files` that share a stem (a.png, a.jpg), the earlier first: they would stand
// for one view, or be written to one output. None when every stem differs.
std::optional<std::pair<std::filesystem::path, std::filesystem::path>> first_shared_stem(
    const std::vector<std::filesystem::path>& files);

// Reads only the header; throws Error naming the file when it is missing or not an image.
ImageHeader read_image_header(const std::filesystem::path& path);
// Decodes a PNG or JPEG keeping its channel count (1, 2, 3 or 4).
Image8 read_image8(const std::filesystem::path& path);

Image to_float(const Image8& image);
Image8 to_8bit(const Image& image);  // rounds and clamps to [0, 255]

// RGB from RGB(A) or gray(+alpha): alpha is composited over `background` (linear, as 3DGS does).
Image composite_rgb(const Image8& image, const float background[3]);

// Writes a PNG through a temporary name and a rename, so a crash never leaves half a file.
void write_png(const std::filesystem::path& path, const Image8& image);
void write_png(const std::filesystem::path& path, const Image& image);
// 16-bit single-channel PNG (e.g. depth), big-endian samples as the PNG standard wants.
void write_png16(const std::filesystem::path& path, const std::vector<uint16_t>& gray, int width,
                 int height);

}  // namespace iesrgs
