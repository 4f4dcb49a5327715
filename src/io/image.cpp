#include "io/image.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <string_view>

#include "core/error.hpp"
#include "core/paths.hpp"
#include "io/atomic_file.hpp"
#include "io/mapped_file.hpp"

// stb_image built here rather than taken from libstb, for two reasons. Only its PNG and JPEG
// decoders: TGA has no signature, so libstb read any unrecognised file as one, and a 20-byte file
// claiming 46000x46000 pixels cost 4 GB before anything could refuse it. And zeroed allocations:
// a progressive JPEG naming a Huffman table no marker defined makes stb 2.27 read that table
// uninitialised.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
namespace {

// Whether one of stb's allocations failed in this thread since the decode began: stb gives no
// reason for some (its first zlib buffer), and would then leave another decoder's stale one.
thread_local bool stb_out_of_memory = false;

void* stb_allocate(size_t size) {
  void* pointer = std::calloc(1, size);
  stb_out_of_memory |= pointer == nullptr;
  return pointer;
}

void* stb_reallocate(void* pointer, size_t size) {
  void* moved = std::realloc(pointer, size);
  stb_out_of_memory |= moved == nullptr && size > 0;
  return moved;
}

}  // namespace

#define STBI_MALLOC(size) stb_allocate(size)
#define STBI_REALLOC(pointer, size) stb_reallocate(pointer, size)
#define STBI_FREE(pointer) std::free(pointer)
#include <stb/stb_image.h>

namespace iesrgs {

namespace fs = std::filesystem;

namespace {

void require_readable(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail_file(path, "image not found");
  if (fs::is_directory(path, ec)) fail_file(path, "is a directory, expected an image");
}

constexpr double kMostPixelsPerByte = 16384;
constexpr double kAnySmallImage = 1 << 20;  // pixels: headers and tables weigh in small files

constexpr std::string_view kPngSignature = "\x89PNG\r\n\x1a\n";

// Why `bytes` cannot be read, as a PNG or a JPEG by their signature: stb tries each decoder in
// turn, so its own reason may be another format's.
std::string unreadable(std::string_view bytes, std::string_view reason) {
  if (bytes.substr(0, kPngSignature.size()) == kPngSignature)
    return fmt::format("not a readable PNG ({})", reason);
  if (bytes.substr(0, 3) == "\xff\xd8\xff") return fmt::format("not a readable JPEG ({})", reason);
  return bytes.empty() ? "empty file, not an image"
                       : "not a PNG or JPEG file (it begins with neither's signature)";
}

std::string decode_problem(std::string_view bytes) {
  if (stb_out_of_memory) return "out of memory while decoding it";
  const char* reason = stbi_failure_reason();
  if (reason && std::string_view(reason) == "too large")  // or damaged: a header's size is read
    return "too large to decode: more than 16777216 pixels a side or 2 GiB of pixels, or its "
           "header is damaged";
  return unreadable(bytes, reason && *reason ? reason : "damaged or truncated");
}

// stb takes the length as an int.
const stbi_uc* stb_bytes(std::string_view bytes, const fs::path& path) {
  if (bytes.size() > size_t(std::numeric_limits<int>::max()))
    fail_file(path, unreadable(bytes, "over 2 GiB"));
  return reinterpret_cast<const stbi_uc*>(bytes.data());
}

uint32_t big_endian32(std::string_view bytes, size_t at) {
  return uint32_t(uint8_t(bytes[at])) << 24 | uint32_t(uint8_t(bytes[at + 1])) << 16 |
         uint32_t(uint8_t(bytes[at + 2])) << 8 | uint32_t(uint8_t(bytes[at + 3]));
}

// stb decodes a PNG without checking its chunks' CRCs, so a flipped byte of the pixel data would
// decode into other pixels without a word. As libpng does, a chunk the image needs (a critical
// one: its type starts upper-case; and tRNS, which stb reads) is refused when its CRC fails;
// other ancillary chunks, which stb skips, are not checked. A chunk reaching past the end of the
// file is refused too: stb would first allocate the length it claims, up to 4 GB.
void check_png_crcs(std::string_view bytes, const fs::path& path) {
  if (bytes.substr(0, kPngSignature.size()) != kPngSignature) return;
  for (size_t at = kPngSignature.size(); at + 12 <= bytes.size();) {
    const uint64_t length = big_endian32(bytes, at);
    if (at + 12 + length > bytes.size())
      fail_file(path, unreadable(bytes, fmt::format("truncated: its chunk {} at byte {} claims "
                                                    "{} bytes, past the end of the file",
                                                    bytes.substr(at + 4, 4), at, length)));
    const std::string_view typed = bytes.substr(at + 4, 4 + length);  // the type and the data
    const std::string_view type = typed.substr(0, 4);
    const bool needed = (type[0] & 0x20) == 0 || type == "tRNS";
    if (needed && uint32_t(crc32_z(0, reinterpret_cast<const Bytef*>(typed.data()),
                                   typed.size())) != big_endian32(bytes, at + 8 + length))
      fail_file(path, fmt::format("damaged: its PNG chunk {} at byte {} fails its CRC", type, at));
    if (type == "IEND") return;
    at += 12 + length;
  }
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

// PNG with every row "Sub"-filtered (each byte minus the one a pixel to the left), which
// compresses photographs and renders well at zlib's fastest level: stb's encoder was the
// bottleneck of caching undistorted 2-Mpixel images. Samples are big-endian as PNG wants.
std::string encode_png(const fs::path& path, const uint8_t* samples, int width, int height,
                       int channels, int bytes_per_sample) {
  static constexpr char kColorType[] = {0, 0, 4, 2, 6};  // by channel count: gray .. RGBA
  if (channels < 1 || channels > 4 || width < 1 || height < 1)
    fail_file(path,
              fmt::format("cannot write a {}x{} PNG with {} channels", width, height, channels));
  const size_t pixel_bytes = size_t(channels) * bytes_per_sample;
  const size_t row_bytes = size_t(width) * pixel_bytes;
  std::string raw(size_t(height) * (1 + row_bytes), '\0');
  for (int y = 0; y < height; ++y) {
    const uint8_t* row = samples + y * row_bytes;
    char* out = &raw[y * (1 + row_bytes)];
    out[0] = 1;  // Sub
    for (size_t b = 0; b < row_bytes; ++b)
      out[1 + b] = char(row[b] - (b >= pixel_bytes ? row[b - pixel_bytes] : 0));
  }
  uLongf packed_size = compressBound(static_cast<uLong>(raw.size()));
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()),
                1) != Z_OK)
    fail_file(path, "PNG compression failed");
  packed.resize(packed_size);

  std::string png("\x89PNG\r\n\x1a\n", 8);
  // IHDR: width, height, bit depth, color type, compression, filter, interlace.
  append_png_chunk(png, "IHDR",
                   be32(width) + be32(height) + char(8 * bytes_per_sample) + kColorType[channels] +
                       std::string(3, '\0'));
  append_png_chunk(png, "IDAT", packed);
  append_png_chunk(png, "IEND", "");
  return png;
}

}  // namespace

std::vector<fs::path> image_files_in(const fs::path& folder) {
  std::vector<fs::path> images;
  std::error_code ec;
  fs::directory_iterator entries(folder, ec);
  if (ec) fail_file(folder, "cannot be read: " + ec.message());
  for (const fs::directory_entry& entry : entries)
    if (entry.is_regular_file() && is_image_file(entry.path())) images.push_back(entry.path());
  if (images.empty()) fail_file(folder, "no PNG or JPEG images in this folder");
  std::sort(images.begin(), images.end());
  return images;
}

std::optional<std::pair<fs::path, fs::path>> first_shared_stem(const std::vector<fs::path>& files) {
  std::map<fs::path, fs::path> by_stem;
  for (const fs::path& file : files)
    if (const auto [it, added] = by_stem.emplace(file.stem(), file); !added)
      return std::make_pair(it->second, file);
  return std::nullopt;
}

ImageHeader read_image_header(const fs::path& path) {
  require_readable(path);
  const MappedFile file(path);  // only the pages of the header are read
  const std::string_view bytes = file.bytes();
  ImageHeader header;
  int channels = 0;
  stb_out_of_memory = false;
  if (!stbi_info_from_memory(stb_bytes(bytes, path), int(bytes.size()), &header.width,
                             &header.height, &channels))
    fail_file(path, decode_problem(bytes));
  return header;
}

Image8 read_image8(const fs::path& path) {
  require_readable(path);
  const MappedFile file(path);
  const std::string_view bytes = file.bytes();
  check_png_crcs(bytes, path);
  int w = 0, h = 0, c = 0;
  const stbi_uc* data = stb_bytes(bytes, path);
  // A header can claim any size; deflate and JPEG's entropy coding cannot pack more than some
  // thousand pixels into a byte (8256 for a 1-bit PNG of one colour), so a claim far beyond that
  // is damage, refused before stb allocates for it.
  if (stbi_info_from_memory(data, int(bytes.size()), &w, &h, &c) &&
      double(w) * double(h) > kMostPixelsPerByte * double(bytes.size()) + kAnySmallImage)
    fail_file(path, fmt::format("damaged: its header claims {}x{} pixels, more than its {} bytes "
                                "can hold",
                                w, h, bytes.size()));
  stb_out_of_memory = false;
  std::unique_ptr<stbi_uc, void (*)(void*)> pixels(
      stbi_load_from_memory(data, int(bytes.size()), &w, &h, &c, 0), stbi_image_free);
  if (!pixels) fail_file(path, decode_problem(bytes));
  try {
    Image8 image(w, h, c);
    std::memcpy(image.data.data(), pixels.get(), image.data.size());
    return image;
  } catch (const std::bad_alloc&) {
    fail_file(path, "out of memory while decoding it");
  }
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
  write_file_atomically(
      path, encode_png(path, image.data.data(), image.width, image.height, image.channels, 1));
}

void write_png(const fs::path& path, const Image& image) {
  write_png(path, to_8bit(image));
}

void write_png16(const fs::path& path, const std::vector<uint16_t>& gray, int width, int height) {
  if (width < 1 || height < 1 || gray.size() != size_t(width) * size_t(height))
    fail_file(path, fmt::format("cannot write {} samples as a {}x{} gray PNG", gray.size(), width,
                                height));
  std::vector<uint8_t> big_endian(gray.size() * 2);
  for (size_t i = 0; i < gray.size(); ++i) {
    big_endian[2 * i] = uint8_t(gray[i] >> 8);
    big_endian[2 * i + 1] = uint8_t(gray[i] & 255);
  }
  write_file_atomically(path, encode_png(path, big_endian.data(), width, height, 1, 2));
}

}  // namespace iesrgs
