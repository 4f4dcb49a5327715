// libFuzzer harness for the COLMAP model parsers: every input is parsed as each of the three
// files in both encodings, and the only acceptable failure is an iesrgs::Error (anything else,
// a crash, a sanitizer report or a huge allocation, is a bug).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.hpp"
#include "io/colmap.hpp"

namespace {

template <typename Parse>
void parse_allowing_errors(Parse parse) {
  try {
    parse();
  } catch (const iesrgs::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::filesystem::path source = "fuzz-input";
  for (const auto encoding : {iesrgs::ColmapEncoding::Binary, iesrgs::ColmapEncoding::Text}) {
    parse_allowing_errors([&] { iesrgs::parse_colmap_cameras(bytes, encoding, source); });
    parse_allowing_errors([&] { iesrgs::parse_colmap_images(bytes, encoding, source); });
    parse_allowing_errors([&] { iesrgs::parse_colmap_points(bytes, encoding, source); });
  }
  return 0;
}
