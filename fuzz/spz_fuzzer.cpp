// Any byte string must either decode into a consistent SplatCloud of finite values with unit
// quaternions or throw iesrgs::Error; the gzip and zstd streams inside are attacker-controlled
// sizes, so a huge allocation is a bug too. Mutating compressed bytes rarely gets past the
// decompressor, so an input that starts with 'U' has the rest gzipped first: the fuzzer then
// mutates the header and attribute streams of versions 2 and 3 directly (fuzz/corpus/spz_fuzzer
// seeds that mode with the test files' uncompressed contents).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>
#include <zlib.h>

#include "core/error.hpp"
#include "io/spz_file.hpp"
#include "splat_cloud_check.hpp"

namespace {

std::string gzipped(std::string_view bytes) {
  z_stream stream{};
  if (deflateInit2(&stream, Z_BEST_SPEED, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) !=
      Z_OK)
    std::abort();
  std::string out(deflateBound(&stream, uLong(bytes.size())), '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  stream.avail_in = uInt(bytes.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = uInt(out.size());
  if (deflate(&stream, Z_FINISH) != Z_STREAM_END) std::abort();
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return out;
}

}  // namespace

// An extension block is warned about on every input that has one: quiet, so the fuzzer runs.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  spdlog::set_level(spdlog::level::err);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const bool compress = size > 0 && data[0] == 'U';
  try {
    const iesrgs::SplatCloud cloud =
        iesrgs::parse_spz(compress ? gzipped(input.substr(1)) : input, "fuzz.spz");
    abort_unless_consistent(cloud);
    abort_unless_finite_with_unit_rotations(cloud);
  } catch (const iesrgs::Error&) {
  }
  return 0;
}
