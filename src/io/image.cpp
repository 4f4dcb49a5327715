#include "io/image.hpp"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

void require_readable(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail_file(path, "image not found");
  if (fs::is_directory(path, ec)) fail_file(path, "is a directory, expected an image");
}

std::string decode_problem() {
  const char* reason = stbi_failure_reason();
  return std::string("not a readable PNG/JPEG (") + (reason ? reason : "unknown reason") + ")";
}

void append_png_chunk(std::string& png, const char* type, const std::string& payload) {
  const uint32_t length = static_cast<uint32_t>(payload.size());
  const unsigned char size_be[4] = {uint8_t(length >> 24), uint8_t(length >> 16),
                                    uint8_t(length >> 8), uint8_t(length)};
  png.append(reinterpret_cast<const char*>(size_be), 4);
  const std::string body = std::string(type, 4) + payload;
  png += body;
  const uint32_t crc = static_cast<uint32_t>(
      crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
  const unsigned char crc_be[4] = {uint8_t(crc >> 24), uint8_t(crc >> 16), uint8_t(crc >> 8),
                                   uint8_t(crc)};
  png.append(reinterpret_cast<const char*>(crc_be), 4);
}

std::string be32(uint32_t v) {
  return {char(v >> 24), char((v >> 16) & 255), char((v >> 8) & 255), char(v & 255)};
}

}  // namespace

ImageHeader read_image_header(const fs::path& path) {
  require_readable(path);
  ImageHeader header;
  if (!stbi_info(path.c_str(), &header.width, &header.height, &header.channels))
    fail_file(path, decode_problem());
  return header;
}

Image8 read_image8(const fs::path& path) {
  require_readable(path);
  int w = 0, h = 0, c = 0;
  std::unique_ptr<stbi_uc, void (*)(void*)> pixels(stbi_load(path.c_str(), &w, &h, &c, 0),
                                                   stbi_image_free);
  if (!pixels) fail_file(path, decode_problem());
  Image8 image(w, h, c);
  std::memcpy(image.data.data(), pixels.get(), image.data.size());
  return image;
}

Image to_float(const Image8& image) {
  Image out(image.width, image.height, image.channels);
  for (size_t i = 0; i < out.data.size(); ++i) out.data[i] = image.data[i] * (1.f / 255.f);
  return out;
}

Image8 to_8bit(const Image& image) {
  Image8 out(image.width, image.height, image.channels);
  for (size_t i = 0; i < out.data.size(); ++i) {
    const float v = std::clamp(image.data[i], 0.f, 1.f) * 255.f;
    out.data[i] = static_cast<uint8_t>(std::lround(v));
  }
  return out;
}

Image composite_rgb(const Image8& image, const float background[3]) {
  Image out(image.width, image.height, 3);
  const int c = image.channels;
  const bool has_alpha = c == 2 || c == 4;
  const bool gray = c <= 2;
  for (size_t p = 0; p < out.pixels(); ++p) {
    const uint8_t* in = &image.data[p * c];
    const float alpha = has_alpha ? in[c - 1] * (1.f / 255.f) : 1.f;
    for (int k = 0; k < 3; ++k) {
      const float v = in[gray ? 0 : k] * (1.f / 255.f);
      out.data[p * 3 + k] = v * alpha + background[k] * (1.f - alpha);
    }
  }
  return out;
}

void write_png(const fs::path& path, const Image8& image) {
  write_atomically(path, [&](const fs::path& tmp) {
    const int stride = image.width * image.channels;
    if (!stbi_write_png(tmp.c_str(), image.width, image.height, image.channels, image.data.data(),
                        stride))
      fail_file(path, "cannot write PNG (disk full or not writable?)");
  });
}

void write_png(const fs::path& path, const Image& image) {
  write_png(path, to_8bit(image));
}

void write_png16(const fs::path& path, const std::vector<uint16_t>& gray, int width, int height) {
  // stb_image_write has no 16-bit mode: filter type 0 per row, zlib stream, three chunks.
  std::string raw;
  raw.reserve(size_t(height) * (1 + 2 * size_t(width)));
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    for (int x = 0; x < width; ++x) {
      const uint16_t v = gray[size_t(y) * width + x];
      raw.push_back(char(v >> 8));
      raw.push_back(char(v & 255));
    }
  }
  uLongf packed_size = compressBound(static_cast<uLong>(raw.size()));
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()),
                6) != Z_OK)
    fail_file(path, "PNG compression failed");
  packed.resize(packed_size);

  std::string png("\x89PNG\r\n\x1a\n", 8);
  // IHDR: width, height, bit depth 16, color type 0 (gray), compression, filter, interlace.
  append_png_chunk(png, "IHDR", be32(width) + be32(height) + std::string("\x10\0\0\0\0", 5));
  append_png_chunk(png, "IDAT", packed);
  append_png_chunk(png, "IEND", "");
  write_file_atomically(path, png);
}

}  // namespace iesrgs
