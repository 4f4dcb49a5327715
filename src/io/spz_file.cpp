#include "io/spz_file.hpp"

#include <fmt/core.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/math.hpp"
#include "io/atomic_file.hpp"
#include "io/viewer_cloud.hpp"

namespace iesrgs {

namespace {

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP" in file order
constexpr uint32_t kVersion = 3;
constexpr uint8_t kAntialiased = 1;
// The reference encoder's precision: 1/4096 of a unit. Fewer bits only where a Gaussian lies
// beyond the 2048 units that 24 bits then reach.
constexpr int kMaxFractionalBits = 12;
constexpr int32_t kFixedLimit = (1 << 23) - 1;
constexpr double kColorScale = 0.15;

void append_u32(std::string& out, uint32_t value) {
  for (int b = 0; b < 4; ++b) out.push_back(char((value >> (8 * b)) & 0xff));
}

int fractional_bits(const SplatCloud& cloud, const std::filesystem::path& path) {
  double reach = 0;
  for (float v : cloud.positions) reach = std::max(reach, std::fabs(double(v)));
  for (int bits = kMaxFractionalBits; bits >= 0; --bits)
    if (std::ldexp(reach, bits) < kFixedLimit) return bits;
  fail_file(path, fmt::format("a Gaussian lies {:g} units from the origin, beyond the {} units "
                              ".spz positions can hold",
                              reach, kFixedLimit));
}

// Little-endian 24-bit two's complement.
void append_positions(std::string& out, const SplatCloud& cloud, int bits) {
  for (float v : cloud.positions) {
    const auto fixed = uint32_t(int32_t(std::lround(std::ldexp(double(v), bits))));
    for (int b = 0; b < 3; ++b) out.push_back(char((fixed >> (8 * b)) & 0xff));
  }
}

// The largest component of the unit quaternion (x y z w order) is dropped and made positive
// (q and -q are the same rotation); its index takes the top two bits, then each other component,
// in order, a sign bit and 9 bits of magnitude, which is at most 1/sqrt(2).
uint32_t smallest_three(const float* wxyz) {
  const double norm = quaternion_norm(wxyz);
  const double q[4] = {wxyz[1] / norm, wxyz[2] / norm, wxyz[3] / norm, wxyz[0] / norm};
  int largest = 0;
  for (int i = 1; i < 4; ++i)
    if (std::fabs(q[i]) > std::fabs(q[largest])) largest = i;
  const bool negate = q[largest] < 0;
  uint32_t packed = uint32_t(largest);
  for (int i = 0; i < 4; ++i) {
    if (i == largest) continue;
    const uint32_t sign = (q[i] < 0) != negate;
    const auto magnitude = std::min(uint32_t(511 * std::fabs(q[i]) * std::sqrt(2.0) + 0.5), 511u);
    packed = packed << 10 | sign << 9 | magnitude;
  }
  return packed;
}

// x * 128 + 128 rounded to the centre of its bucket of 2^(8 - bits) values, so that gzip finds
// the repeated low bits; 0 stays exact.
uint8_t quantize_sh(float x, int bits) {
  const int bucket = 1 << (8 - bits);
  const int q = int(std::lround(double(x) * 128)) + 128;
  return uint8_t(std::clamp((q + bucket / 2) / bucket * bucket, 0, 255));
}

std::string encode(const SplatCloud& cloud, uint8_t flags, int bits) {
  const size_t n = cloud.size();
  const size_t rest = n ? cloud.sh_rest.size() / n : 0;  // (K - 1) * 3 per Gaussian
  std::string out;
  out.reserve(16 + n * (9 + 1 + 3 + 3 + 4 + rest));
  append_u32(out, kMagic);
  append_u32(out, kVersion);
  append_u32(out, uint32_t(n));
  out.push_back(char(cloud.sh_degree));
  out.push_back(char(bits));
  out.push_back(char(flags));
  out.push_back('\0');
  append_positions(out, cloud, bits);
  for (float o : cloud.opacity) out.push_back(char(to_byte(sigmoid(o) * 255)));
  for (float dc : cloud.sh_dc) out.push_back(char(to_byte((kColorScale * dc + 0.5) * 255)));
  for (float s : cloud.log_scales) out.push_back(char(to_byte((s + 10) * 16)));
  for (size_t i = 0; i < n; ++i) append_u32(out, smallest_three(&cloud.rotations[4 * i]));
  // Coefficient-major, colour-minor, like the cloud's f_rest: the first 9 values are degree 1.
  for (size_t j = 0; j < cloud.sh_rest.size(); ++j)
    out.push_back(char(quantize_sh(cloud.sh_rest[j], j % rest < 9 ? 5 : 4)));
  return out;
}

std::string gzip(const std::string& bytes, const std::filesystem::path& path) {
  z_stream stream{};
  if (deflateInit2(&stream, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 8,
                   Z_DEFAULT_STRATEGY) != Z_OK)
    fail_file(path, "gzip initialisation failed");
  std::string out;
  char buffer[1 << 16];
  size_t consumed = 0;
  int status = Z_OK;
  while (status == Z_OK) {
    const size_t chunk = std::min<size_t>(bytes.size() - consumed, 1u << 30);
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + consumed));
    stream.avail_in = uInt(chunk);
    const bool last = consumed + chunk == bytes.size();
    do {
      stream.next_out = reinterpret_cast<Bytef*>(buffer);
      stream.avail_out = sizeof buffer;
      status = deflate(&stream, last ? Z_FINISH : Z_NO_FLUSH);
      out.append(buffer, sizeof buffer - stream.avail_out);
    } while (stream.avail_out == 0 && status == Z_OK);
    consumed += chunk;
  }
  deflateEnd(&stream);
  if (status != Z_STREAM_END) fail_file(path, "gzip compression failed");
  return out;
}

}  // namespace

void write_spz(const std::filesystem::path& path, const SplatCloud& cloud) {
  const SplatCloud baked = viewer_cloud(cloud, path);
  const uint8_t flags = cloud.has_filter_3d() ? kAntialiased : 0;
  write_file_atomically(path, gzip(encode(baked, flags, fractional_bits(baked, path)), path));
}

}  // namespace iesrgs
