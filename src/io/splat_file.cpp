#include "io/splat_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/math.hpp"
#include "io/atomic_file.hpp"
#include "io/non_finite_records.hpp"
#include "io/viewer_cloud.hpp"

namespace iesrgs {

namespace {

// What a viewer streams first: the product of the scales times the opacity, in log space.
std::vector<size_t> most_visible_first(const SplatCloud& cloud) {
  std::vector<double> key(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i)
    key[i] = double(cloud.log_scales[3 * i]) + cloud.log_scales[3 * i + 1] +
             cloud.log_scales[3 * i + 2] - std::log1p(std::exp(-double(cloud.opacity[i])));
  std::vector<size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key[a] > key[b]; });
  return order;
}

// Appends record i, unless a position or scale is not finite (left_out says so).
void read_record(const char* at, size_t i, const std::filesystem::path& name, SplatCloud& cloud,
                 NonFiniteRecords& left_out) {
  float floats[6];
  std::memcpy(floats, at, sizeof floats);
  for (int k = 0; k < 6; ++k)
    if (!std::isfinite(floats[k]))
      return left_out.add([&] {
        return fmt::format("record {}: {} {} is not finite", i, k < 3 ? "position" : "scale",
                           floats[k]);
      });
  for (int k = 0; k < 3; ++k) {
    const float scale = floats[3 + k];
    if (scale < 0) fail_file(name, fmt::format("record {}: scale {} is negative", i, scale));
    cloud.log_scales.push_back(std::log(std::max(scale, std::numeric_limits<float>::min())));
  }
  cloud.positions.insert(cloud.positions.end(), floats, floats + 3);
  const auto* bytes = reinterpret_cast<const uint8_t*>(at + sizeof floats);
  for (int k = 0; k < 3; ++k) cloud.sh_dc.push_back(float((bytes[k] / 255.0 - 0.5) / kShC0));
  cloud.opacity.push_back(opacity_logit_of_byte(bytes[3]));
  float q[4];
  for (int k = 0; k < 4; ++k) q[k] = float((bytes[4 + k] - 128) / 128.0);
  const double norm = quaternion_norm(q);
  for (int k = 0; k < 4; ++k)
    cloud.rotations.push_back(norm > 0 ? float(q[k] / norm) : float(k == 0));
}

void append_record(std::string& bytes, const SplatCloud& cloud, size_t i) {
  float floats[6];
  for (int k = 0; k < 3; ++k) {
    floats[k] = cloud.positions[3 * i + k];
    floats[3 + k] = std::exp(cloud.log_scales[3 * i + k]);
  }
  const float* q = &cloud.rotations[4 * i];
  const double norm = quaternion_norm(q);
  uint8_t tail[8];
  for (int k = 0; k < 3; ++k) tail[k] = to_byte((0.5 + kShC0 * cloud.sh_dc[3 * i + k]) * 255);
  tail[3] = to_byte(sigmoid(cloud.opacity[i]) * 255);
  for (int k = 0; k < 4; ++k) tail[4 + k] = to_byte(q[k] / norm * 128 + 128);
  const size_t at = bytes.size();
  bytes.resize(at + kSplatRecordBytes);
  std::memcpy(&bytes[at], floats, sizeof floats);
  std::memcpy(&bytes[at + sizeof floats], tail, sizeof tail);
}

}  // namespace

size_t write_splat(const std::filesystem::path& path, const SplatCloud& cloud) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, ".splat floats are little-endian");
  const SplatCloud baked = viewer_cloud(cloud, path);
  std::string bytes;
  bytes.reserve(baked.size() * kSplatRecordBytes);
  for (size_t i : most_visible_first(baked)) append_record(bytes, baked, i);
  write_file_atomically(path, bytes);
  return baked.size();
}

SplatCloud parse_splat(std::string_view bytes, const std::filesystem::path& name) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, ".splat floats are little-endian");
  if (bytes.empty()) fail_file(name, "is empty: no Gaussians");
  if (bytes.size() % kSplatRecordBytes != 0)
    fail_file(name, fmt::format("is {} bytes, not a whole number of {}-byte .splat records",
                                bytes.size(), kSplatRecordBytes));
  SplatCloud cloud;
  cloud.antialiased = false;
  NonFiniteRecords left_out(name, "Gaussian");
  const size_t count = bytes.size() / kSplatRecordBytes;
  for (size_t i = 0; i < count; ++i)
    read_record(bytes.data() + i * kSplatRecordBytes, i, name, cloud, left_out);
  left_out.report(count);
  return cloud;
}

SplatCloud read_splat(const std::filesystem::path& path) {
  return parse_splat(read_file(path), path);
}

}  // namespace iesrgs
