#include "io/spz_file.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <new>
#include <string>

#include "core/byte_reader.hpp"
#include "core/error.hpp"
#include "core/math.hpp"
#include "io/atomic_file.hpp"
#include "io/viewer_cloud.hpp"

namespace iesrgs {

namespace {

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP" in file order
constexpr uint32_t kVersion = 3;
constexpr uint32_t kOldestReadVersion = 2;  // version 1 (float16 positions) was never released
constexpr uint32_t kFirstSmallestThreeVersion = 3;  // 4-byte rotations; 3 bytes (x y z) before
constexpr uint32_t kFirstZstdVersion = 4;           // a stream per attribute, each zstd-compressed
constexpr uint32_t kNewestReadVersion = 4;
constexpr int kSpzMaxShDegree = 4;  // the format's; bands above the cloud's are dropped
constexpr uint8_t kAntialiased = 1;
constexpr uint8_t kHasExtensions = 2;
// No attribute stream compresses better than this; a larger claim is a corrupt file.
constexpr uint64_t kMaxCompressionRatio = 1024;
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

// ---- Reading ----

struct SpzHeader {
  uint32_t version = 0, count = 0;
  int sh_degree = 0, bits = 0;
  uint8_t flags = 0;
};

int rotation_bytes(const SpzHeader& h) {
  return h.version >= kFirstSmallestThreeVersion ? 4 : 3;
}

// Uncompressed sizes of the attribute streams, in file order: positions, opacities, colours,
// scales, rotations, higher SH bands.
std::vector<uint64_t> stream_sizes(const SpzHeader& h) {
  const uint64_t n = h.count, rest = 3 * (uint64_t(h.sh_degree + 1) * (h.sh_degree + 1) - 1);
  return {9 * n, n, 3 * n, 3 * n, rotation_bytes(h) * n, rest * n};
}

uint64_t total_bytes(const std::vector<uint64_t>& sizes) {
  uint64_t sum = 0;
  for (uint64_t s : sizes) sum += s;
  return sum;
}

// The part of the header every version shares, after magic and version.
SpzHeader read_spz_header(ByteReader& in, uint32_t version) {
  SpzHeader h;
  h.version = version;
  if (version < kOldestReadVersion || version > kNewestReadVersion)
    throw FormatError(fmt::format("unsupported .spz version {} (versions {} to {} are read)",
                                  version, kOldestReadVersion, kNewestReadVersion));
  h.count = in.little<uint32_t>();
  h.sh_degree = in.little<uint8_t>();
  h.bits = in.little<uint8_t>();
  h.flags = in.little<uint8_t>();
  if (h.sh_degree > kSpzMaxShDegree)
    throw FormatError(fmt::format("SH degree {} is above {}", h.sh_degree, kSpzMaxShDegree));
  if (h.bits > 23) throw FormatError(fmt::format("{} fractional bits exceed 23", h.bits));
  if (h.flags & kHasExtensions)
    spdlog::warn(".spz extensions are not read; the Gaussians are decoded without them");
  return h;
}

std::string gunzip(std::string_view compressed) {
  z_stream stream{};
  if (inflateInit2(&stream, 16 + MAX_WBITS) != Z_OK)
    throw FormatError("zlib initialisation failed");
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  stream.avail_in = uInt(compressed.size());
  std::string out;
  char buffer[1 << 16];
  int status = Z_OK;
  while (status == Z_OK && out.size() <= compressed.size() * kMaxCompressionRatio) {
    stream.next_out = reinterpret_cast<Bytef*>(buffer);
    stream.avail_out = sizeof buffer;
    status = inflate(&stream, Z_NO_FLUSH);
    out.append(buffer, sizeof buffer - stream.avail_out);
  }
  inflateEnd(&stream);
  if (status != Z_STREAM_END) throw FormatError("corrupt or truncated gzip stream");
  return out;
}

// Versions 2 and 3: one gzip stream of a 16-byte header and the attribute streams.
std::string legacy_streams(std::string_view file, SpzHeader& h) {
  const std::string bytes = gunzip(file);
  ByteReader in(bytes);
  if (in.little<uint32_t>() != kMagic) throw FormatError("not an .spz file (no NGSP header)");
  const uint32_t version = in.little<uint32_t>();
  if (version >= kFirstZstdVersion)
    throw FormatError(fmt::format("version {} inside a gzip stream", version));
  h = read_spz_header(in, version);
  in.take(1);  // reserved
  // Extensions, if any, follow the streams.
  return std::string(in.take(total_bytes(stream_sizes(h))));
}

std::string unzstd(std::string_view compressed, uint64_t size) {
  std::string out(size, '\0');
  const size_t written = ZSTD_decompress(out.data(), size, compressed.data(), compressed.size());
  if (ZSTD_isError(written) || written != size)
    throw FormatError("corrupt zstd stream in the .spz file");
  return out;
}

// Version 4: a 32-byte header, extensions, a table of (compressed, uncompressed) sizes, then one
// zstd frame per non-empty attribute stream.
std::string zstd_streams(std::string_view file, SpzHeader& h) {
  ByteReader in(file);
  in.take(4);  // magic
  const uint32_t version = in.little<uint32_t>();
  if (version < kFirstZstdVersion)
    throw FormatError(fmt::format("version {} without its gzip stream", version));
  h = read_spz_header(in, version);
  const int stream_count = in.little<uint8_t>();
  ByteReader table(file, in.little<uint32_t>());
  std::vector<uint64_t> sizes = stream_sizes(h);
  sizes.erase(std::remove(sizes.begin(), sizes.end(), 0), sizes.end());
  if (stream_count != int(sizes.size()))
    throw FormatError(fmt::format("{} attribute streams where {} Gaussians of SH degree {} need {}",
                                  stream_count, h.count, h.sh_degree, sizes.size()));
  // The slack of 64 bytes covers a zstd frame's own header on tiny streams.
  std::vector<uint64_t> compressed(sizes.size());
  for (size_t s = 0; s < sizes.size(); ++s) {
    compressed[s] = table.little<uint64_t>();
    if (table.little<uint64_t>() != sizes[s] ||
        sizes[s] > (compressed[s] + 64) * kMaxCompressionRatio)
      throw FormatError(
          fmt::format("attribute stream {} has the wrong size for {} Gaussians", s, h.count));
  }
  std::string streams;
  for (size_t s = 0; s < sizes.size(); ++s) streams += unzstd(table.take(compressed[s]), sizes[s]);
  return streams;
}

float fixed_position(std::string_view bytes, size_t i, int bits) {
  uint32_t fixed = 0;
  for (int b = 0; b < 3; ++b) fixed |= uint32_t(uint8_t(bytes[3 * i + b])) << (8 * b);
  if (fixed & 0x800000) fixed |= 0xff000000;  // sign extension
  return float(std::ldexp(double(int32_t(fixed)), -bits));
}

// Both rotation encodings store three components and let the fourth complete a unit vector.
// Bytes no encoder writes can make the three longer than 1 on their own: the quaternion is then
// normalized, as a renderer would, so that every decoded rotation is a unit one.
void complete_unit_quaternion(double xyzw[4], int missing, float* wxyz) {
  double sum = 0;
  for (int i = 0; i < 4; ++i)
    if (i != missing) sum += xyzw[i] * xyzw[i];
  xyzw[missing] = std::sqrt(std::max(0.0, 1 - sum));
  const double norm = std::sqrt(std::max(1.0, sum));
  const int order[4] = {3, 0, 1, 2};
  for (int k = 0; k < 4; ++k) wxyz[k] = float(xyzw[order[k]] / norm);
}

// Inverse of smallest_three, to (w x y z).
void unpack_smallest_three(uint32_t packed, float* wxyz) {
  const int largest = int(packed >> 30);
  double q[4] = {};  // x y z w
  for (int i = 3; i >= 0; --i) {
    if (i == largest) continue;
    const double magnitude = double(packed & 511) / 511 / std::sqrt(2.0);
    q[i] = packed >> 9 & 1 ? -magnitude : magnitude;
    packed >>= 10;
  }
  complete_unit_quaternion(q, largest, wxyz);
}

// Version 2's rotations: x y z of the unit quaternion with w >= 0, one byte each.
void unpack_first_three(const char* bytes, float* wxyz) {
  double q[4] = {};
  for (int k = 0; k < 3; ++k) q[k] = uint8_t(bytes[k]) / 127.5 - 1;
  complete_unit_quaternion(q, 3, wxyz);
}

SplatCloud decode_streams(const SpzHeader& h, const std::string& streams) {
  const size_t n = h.count;
  ByteReader in(streams);
  SplatCloud cloud;
  cloud.sh_degree = h.sh_degree;
  cloud.antialiased = h.flags & kAntialiased;
  const std::string_view positions = in.take(9 * n);
  for (size_t i = 0; i < 3 * n; ++i)
    cloud.positions.push_back(fixed_position(positions, i, h.bits));
  for (char c : in.take(n)) cloud.opacity.push_back(opacity_logit_of_byte(uint8_t(c)));
  for (char c : in.take(3 * n))
    cloud.sh_dc.push_back(float((uint8_t(c) / 255.0 - 0.5) / kColorScale));
  for (char c : in.take(3 * n)) cloud.log_scales.push_back(float(uint8_t(c) / 16.0 - 10));
  cloud.rotations.resize(4 * n);
  const int width = rotation_bytes(h);
  const std::string_view rotations = in.take(width * n);
  for (size_t i = 0; i < n; ++i) {
    const char* r = rotations.data() + width * i;
    if (width == 4)
      unpack_smallest_three(ByteReader(std::string_view(r, 4)).little<uint32_t>(),
                            &cloud.rotations[4 * i]);
    else
      unpack_first_three(r, &cloud.rotations[4 * i]);
  }
  for (char c : in.take(in.remaining())) cloud.sh_rest.push_back(float((uint8_t(c) - 128) / 128.0));
  return cloud;
}

// The renderer draws SH up to degree 3: a degree-4 cloud keeps its first 15 coefficients per
// channel, the bands every 3DGS tool draws, and loses the fourth band's view-dependent detail.
void drop_fourth_band(SplatCloud& cloud, const std::filesystem::path& name) {
  if (cloud.sh_degree <= kMaxCloudShDegree) return;
  spdlog::warn("{}: SH degree {} read up to degree {}; the higher band is dropped", name.string(),
               cloud.sh_degree, kMaxCloudShDegree);
  const size_t from = 3 * (size_t(cloud.sh_degree + 1) * (cloud.sh_degree + 1) - 1);
  const size_t to = 3 * (size_t(kMaxCloudShDegree + 1) * (kMaxCloudShDegree + 1) - 1);
  for (size_t i = 0; i < cloud.size(); ++i)
    std::copy_n(cloud.sh_rest.begin() + i * from, to, cloud.sh_rest.begin() + i * to);
  cloud.sh_rest.resize(cloud.size() * to);
  cloud.sh_degree = kMaxCloudShDegree;
}

}  // namespace

size_t write_spz(const std::filesystem::path& path, const SplatCloud& cloud) {
  const SplatCloud baked = viewer_cloud(cloud, path);
  const uint8_t flags = cloud.antialiased ? kAntialiased : 0;
  write_file_atomically(path, gzip(encode(baked, flags, fractional_bits(baked, path)), path));
  return baked.size();
}

SplatCloud parse_spz(std::string_view bytes, const std::filesystem::path& name) {
  try {
    SpzHeader header;
    const bool gzipped =
        bytes.size() >= 2 && uint8_t(bytes[0]) == 0x1f && uint8_t(bytes[1]) == 0x8b;
    if (!gzipped && (bytes.size() < 4 || ByteReader(bytes).little<uint32_t>() != kMagic))
      throw FormatError("not an .spz file (neither gzip nor an NGSP header)");
    const std::string streams =
        gzipped ? legacy_streams(bytes, header) : zstd_streams(bytes, header);
    SplatCloud cloud = decode_streams(header, streams);
    drop_fourth_band(cloud, name);
    return cloud;
  } catch (const FormatError& e) {
    fail_file(name, e.what());
  } catch (const std::bad_alloc&) {  // sizes up to 1024x the file's pass the checks above
    fail_file(name, "not enough memory to decode it");
  }
}

SplatCloud read_spz(const std::filesystem::path& path) {
  return parse_spz(read_file(path), path);
}

}  // namespace iesrgs
