#include <gtest/gtest.h>
#include <zlib.h>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "support/child_process.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

// A decoder of its own for the 16-bit PNGs, which the project never reads back.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>

namespace iesrgs {
namespace {

using testing::error_message;
using testing::TempDir;
using testing::write_text;

// `png` with its header's size replaced, and the header's CRC made right for it.
std::string with_size(std::string png, uint32_t width, uint32_t height) {
  for (int k = 0; k < 4; ++k) {
    png[16 + k] = char(width >> (24 - 8 * k));
    png[20 + k] = char(height >> (24 - 8 * k));
  }
  const uLong crc = crc32(0, reinterpret_cast<const Bytef*>(png.data() + 12), 17);
  for (int k = 0; k < 4; ++k) png[29 + k] = char(crc >> (24 - 8 * k));
  return png;
}

Image8 gradient(int w, int h, int c) {
  Image8 image(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) image.at(x, y, k) = uint8_t((x * 7 + y * 13 + k * 50) % 256);
  return image;
}

TEST(Image, PngRoundTripKeepsEveryChannel) {
  TempDir dir;
  for (int channels = 1; channels <= 4; ++channels) {
    const Image8 image = gradient(13, 7, channels);
    const auto path = dir / ("g" + std::to_string(channels) + ".png");
    write_png(path, image);
    const Image8 back = read_image8(path);
    EXPECT_EQ(back.channels, channels);
    EXPECT_EQ(back.data, image.data);
    const ImageHeader header = read_image_header(path);
    EXPECT_EQ(header.width, 13);
    EXPECT_EQ(header.height, 7);
  }
}

TEST(Image, CompositeOverBackground) {
  Image8 rgba(2, 1, 4);
  rgba.data = {255, 0, 0, 255, /* opaque red */ 0, 0, 255, 0 /* transparent */};
  const float white[3] = {1, 1, 1};
  const Image rgb = composite_rgb(rgba, white);
  EXPECT_FLOAT_EQ(rgb.at(0, 0, 0), 1.f);
  EXPECT_FLOAT_EQ(rgb.at(0, 0, 1), 0.f);
  EXPECT_FLOAT_EQ(rgb.at(1, 0, 0), 1.f);
  EXPECT_FLOAT_EQ(rgb.at(1, 0, 2), 1.f);
  Image8 half(1, 1, 4);
  half.data = {0, 0, 0, 128};
  EXPECT_NEAR(composite_rgb(half, white).at(0, 0, 0), 1 - 128 / 255.f, 1e-6);
}

TEST(Image, Png16IsReadBackExactly) {
  TempDir dir;
  std::vector<uint16_t> depth{0, 1, 256, 65535, 1234, 40000};
  write_png16(dir / "d.png", depth, 3, 2);
  int w, h, c;
  stbi_us* pixels = stbi_load_16((dir / "d.png").c_str(), &w, &h, &c, 0);
  ASSERT_NE(pixels, nullptr);
  EXPECT_EQ(w, 3);
  EXPECT_EQ(h, 2);
  EXPECT_EQ(c, 1);
  EXPECT_EQ(std::vector<uint16_t>(pixels, pixels + 6), depth);
  stbi_image_free(pixels);
}

TEST(Image, Png16OfTheWrongSampleCountIsRefused) {
  TempDir dir;
  const std::string message =
      error_message([&] { write_png16(dir / "d.png", std::vector<uint16_t>(5), 3, 2); });
  EXPECT_NE(message.find("cannot write 5 samples as a 3x2 gray PNG"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(dir / "d.png"));
}

TEST(Image, ToEightBitRoundsAndClamps) {
  Image image(4, 1, 1);
  image.data = {-0.5f, 0.5f, 1.5f, 0.2f};
  EXPECT_EQ(to_8bit(image).data, (std::vector<uint8_t>{0, 128, 255, 51}));
}

TEST(Image, FolderListingTakesItsImagesInNameOrder) {
  TempDir dir;
  for (const char* name : {"b.JPG", "a.png", "c.jpeg", "notes.txt", "depth.npy"})
    write_text(dir / name, "");
  std::filesystem::create_directory(dir / "sub.png");  // a folder, whatever its name
  const std::vector<std::filesystem::path> images = image_files_in(dir.path());
  ASSERT_EQ(images.size(), 3u);
  EXPECT_EQ(images[0].filename(), "a.png");
  EXPECT_EQ(images[1].filename(), "b.JPG");
  EXPECT_EQ(images[2].filename(), "c.jpeg");
  std::filesystem::create_directory(dir / "empty");
  EXPECT_EQ(error_message([&] { image_files_in(dir / "empty"); }),
            (dir / "empty").string() + ": no PNG or JPEG images in this folder");
}

TEST(Image, MissingFileIsNamed) {
  TempDir dir;
  const std::string message = error_message([&] { read_image8(dir / "nope.png"); });
  EXPECT_NE(message.find("nope.png: image not found"), std::string::npos) << message;
}

TEST(Image, CorruptFilesAreNamed) {
  TempDir dir;
  write_png(dir / "ok.png", gradient(64, 64, 3));
  const std::string png = read_file(dir / "ok.png");
  write_text(dir / "truncated.png", png.substr(0, png.size() / 2));
  write_text(dir / "garbage.jpg", "this is not a JPEG at all");
  write_text(dir / "empty.png", "");
  // A run-length TGA header claiming 46000x46000 pixels: TGA, which has no signature, is not an
  // image format read here, so no file of another kind decodes as one.
  write_text(dir / "tga.png",
             std::string("\0\0\x0a\0\0\0\0\0\0\0\0\0\xb0\xb3\xb0\xb3\x18\0\0\0", 20));
  EXPECT_NE(error_message([&] {
              read_image8(dir / "truncated.png");
            }).find("truncated.png: not a readable PNG (truncated: its chunk IDAT"),
            std::string::npos);
  // A file is named as the kind its signature says, whichever decoder stb tried last.
  write_text(dir / "cut.jpg", std::string("\xff\xd8\xff\xe0\0\x10JFIF", 10));
  const std::pair<const char*, const char*> cases[] = {
      {"cut.jpg", "not a readable JPEG ("},
      {"garbage.jpg", "not a PNG or JPEG file (it begins with neither's signature)"},
      {"empty.png", "empty file, not an image"},
      {"tga.png", "not a PNG or JPEG file"}};
  for (const auto& [name, problem] : cases) {
    for (const std::string& message : {error_message([&] { read_image8(dir / name); }),
                                       error_message([&] { read_image_header(dir / name); })})
      EXPECT_NE(message.find(std::string(name) + ": " + problem), std::string::npos) << message;
  }
}

// A flipped byte of the pixel data still inflates, into other pixels: the chunk's CRC tells.
// 0 when decoding `png` fails, out of memory, with a message saying so.
int decode_out_of_memory(const std::filesystem::path& png) {
  const std::string message = error_message([&] { read_image8(png); });
  return message == png.string() + ": out of memory while decoding it" ? 0 : 1;
}

// Out of memory while decoding is said as such: stb gives its zlib buffer's failure no reason,
// which left a JPEG check's "no SOI" to call the PNG unreadable.
TEST(Image, OutOfMemoryWhileDecodingIsNamed) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's allocator ends the process rather than fail an allocation";
#endif
  TempDir dir;
  const auto png = dir / "large.png";
  write_png(png, Image8(4096, 4096, 3));  // 48 MiB of pixels in a small file
  EXPECT_EQ(
      testing::exit_status_with_memory_to_spare(8 << 20, [&] { return decode_out_of_memory(png); }),
      0);
  EXPECT_EQ(read_image8(png).width, 4096);
}

TEST(Image, APngWhoseDataFailsItsCrcIsDamaged) {
  TempDir dir;
  write_png(dir / "ok.png", gradient(64, 64, 3));
  std::string png = read_file(dir / "ok.png");
  const size_t data = png.find("IDAT");
  png[data + 40] = char(png[data + 40] ^ 0x55);
  write_text(dir / "flipped.png", png);
  EXPECT_EQ(error_message([&] { read_image8(dir / "flipped.png"); }),
            (dir / "flipped.png").string() + ": damaged: its PNG chunk IDAT at byte " +
                std::to_string(data - 4) + " fails its CRC");
  const size_t end = png.find("IEND");
  write_text(dir / "no_end.png", read_file(dir / "ok.png").substr(0, end - 4));
  // stb wants the end chunk, and says nothing of why: the message does.
  EXPECT_EQ(error_message([&] { read_image8(dir / "no_end.png"); }),
            (dir / "no_end.png").string() + ": not a readable PNG (damaged or truncated)");
  // A header claiming 2^25 pixels a side: stb's bare "too large" is explained.
  write_text(dir / "huge.png", with_size(read_file(dir / "ok.png"), 1 << 25, 64));
  EXPECT_NE(error_message([&] {
              read_image8(dir / "huge.png");
            }).find("too large to decode: more than 16777216 pixels a side"),
            std::string::npos);
  // 15000x15000 pixels in some hundred bytes: refused before stb allocates 675 MB for them.
  const std::string claimed = with_size(read_file(dir / "ok.png"), 15000, 15000);
  write_text(dir / "claims.png", claimed);
  EXPECT_EQ(error_message([&] { read_image8(dir / "claims.png"); }),
            (dir / "claims.png").string() + ": damaged: its header claims 15000x15000 pixels, " +
                "more than its " + std::to_string(claimed.size()) + " bytes can hold");
  // A chunk claiming 1.1 GB in a file of some hundred bytes: refused before stb allocates them.
  std::string long_chunk = read_file(dir / "ok.png");
  const size_t idat = long_chunk.find("IDAT") - 4;
  long_chunk.replace(idat, 4, "DIDA");
  write_text(dir / "long_chunk.png", long_chunk);
  EXPECT_EQ(error_message([&] { read_image8(dir / "long_chunk.png"); }),
            (dir / "long_chunk.png").string() +
                ": not a readable PNG (truncated: its chunk IDAT at byte " + std::to_string(idat) +
                " claims 1145652289 bytes, past the end of the file)");
  // A text chunk, which stb skips, with a wrong CRC: libpng warns and reads the image, as here.
  std::string text = read_file(dir / "ok.png");
  text.insert(33, std::string("\0\0\0\5tEXta\0bcd\0\0\0\0", 17));  // after IHDR
  write_text(dir / "text.png", text);
  EXPECT_EQ(read_image8(dir / "text.png").data, gradient(64, 64, 3).data);
}

}  // namespace
}  // namespace iesrgs
