#include "io/splat_file.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>

#include "core/error.hpp"
#include "core/math.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs {

namespace {

uint8_t to_byte(double value) {
  return uint8_t(std::clamp(std::lround(value), 0L, 255L));
}

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

double quaternion_norm(const float* q) {
  return std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] +
                   double(q[3]) * q[3]);
}

// Before sorting, which needs finite keys; a scale must stay finite once exponentiated.
void check_finite(const SplatCloud& cloud, const std::filesystem::path& path) {
  auto finite = [](const std::vector<float>& values, size_t from, bool exponentiated) {
    return std::all_of(values.begin() + from, values.begin() + from + 3,
                       [&](float v) { return std::isfinite(exponentiated ? std::exp(v) : v); });
  };
  for (size_t i = 0; i < cloud.size(); ++i) {
    const double norm = quaternion_norm(&cloud.rotations[4 * i]);
    if (!finite(cloud.positions, 3 * i, false) || !finite(cloud.log_scales, 3 * i, true) ||
        !finite(cloud.sh_dc, 3 * i, false) || !std::isfinite(cloud.opacity[i]) ||
        !std::isfinite(norm) || norm == 0)
      fail_file(path, fmt::format("Gaussian {} has a non-finite or degenerate parameter", i));
  }
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

void write_splat(const std::filesystem::path& path, const SplatCloud& cloud) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, ".splat floats are little-endian");
  check_splat_cloud(cloud, path);
  const SplatCloud baked = bake_filter_3d(cloud);
  check_finite(baked, path);
  std::string bytes;
  bytes.reserve(baked.size() * kSplatRecordBytes);
  for (size_t i : most_visible_first(baked)) append_record(bytes, baked, i);
  write_file_atomically(path, bytes);
}

}  // namespace iesrgs
