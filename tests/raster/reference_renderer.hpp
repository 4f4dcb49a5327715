#pragma once
// Slow, straightforward double-precision renderer that the kernels are checked against: every
// pixel against every projected Gaussian, sorted once by depth, written independently of the
// kernels' math (host Vec3 / Mat3, SH as 3DGS's polynomial).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "core/math.hpp"
#include "io/camera.hpp"
#include "raster_test_scene.hpp"

namespace iesrgs::raster::testkit {

// 3DGS's cut-offs, written out rather than taken from the kernels' header, as the float values
// the kernels compare with: alpha capped at 0.99, splats under 1/255 skipped, a pixel stopped
// before its transmittance would drop under 1e-4.
constexpr double kAlphaCap = 0.99f, kAlphaSkip = 1.0f / 255.0f, kTransmittanceStop = 1e-4f;

struct ReferenceImage {
  int width = 0, height = 0;
  std::vector<double> image, alpha, depth;  // (3, H, W), (H, W), (H, W)
};

struct ReferenceSplat {
  double x, y, depth, opacity;
  double conic[3];  // xx, xy, yy
  double color[3];
};

inline double sh_channel(int degree, const double* dc, const double* rest, int c, const Vec3& d) {
  const double x = d.x, y = d.y, z = d.z;
  const auto k = [&](int i) { return i == 0 ? dc[c] : rest[3 * (i - 1) + c]; };
  double r = 0.28209479177387814 * k(0);
  if (degree > 0) r += 0.4886025119029199 * (-y * k(1) + z * k(2) - x * k(3));
  if (degree > 1)
    r += 1.0925484305920792 * x * y * k(4) - 1.0925484305920792 * y * z * k(5) +
         0.31539156525252005 * (2 * z * z - x * x - y * y) * k(6) -
         1.0925484305920792 * x * z * k(7) + 0.5462742152960396 * (x * x - y * y) * k(8);
  if (degree > 2)
    r += -0.5900435899266435 * y * (3 * x * x - y * y) * k(9) +
         2.890611442640554 * x * y * z * k(10) -
         0.4570457994644658 * y * (4 * z * z - x * x - y * y) * k(11) +
         0.3731763325901154 * z * (2 * z * z - 3 * x * x - 3 * y * y) * k(12) -
         0.4570457994644658 * x * (4 * z * z - x * x - y * y) * k(13) +
         1.445305721320277 * z * (x * x - y * y) * k(14) -
         0.5900435899266435 * x * (x * x - 3 * y * y) * k(15);
  return std::max(0.0, r + 0.5);
}

// False when culled (near plane, degenerate).
inline bool reference_project(const Scene<double>& s, int i, const Camera& cam,
                              ReferenceSplat& out) {
  const Intrinsics& k = cam.intrinsics;
  const Vec3 mean{s.means[3 * i], s.means[3 * i + 1], s.means[3 * i + 2]};
  const Vec3 v = cam.rotation * mean + cam.translation;
  if (v.z <= 0.2) return false;
  const double* q = &s.quats[4 * i];
  const double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const Mat3 rot = iesrgs::quat_to_rotation(q[0] / qn, q[1] / qn, q[2] / qn, q[3] / qn);
  Mat3 var;
  double ratio3d = 1;
  for (int a = 0; a < 3; ++a) {
    const double s2 = std::exp(2 * s.log_scales[3 * i + a]);
    var(a, a) = s2 + s.filter_std[i] * s.filter_std[i];
    ratio3d *= s2 / var(a, a);
  }
  const Mat3 sigma = rot * var * rot.transposed();
  // The Jacobian is clamped 0.3 half-widths beyond the image edges, seen from the principal point.
  const double margin_x = 0.15 * k.width / k.fx, margin_y = 0.15 * k.height / k.fy;
  const double tx =
      std::clamp(v.x / v.z, -k.cx / k.fx - margin_x, (k.width - k.cx) / k.fx + margin_x) * v.z;
  const double ty =
      std::clamp(v.y / v.z, -k.cy / k.fy - margin_y, (k.height - k.cy) / k.fy + margin_y) * v.z;
  Mat3 j;  // third row zero
  j.m = {k.fx / v.z, 0, -k.fx * tx / (v.z * v.z), 0, k.fy / v.z, -k.fy * ty / (v.z * v.z), 0, 0, 0};
  const Mat3 t = j * cam.rotation;
  const Mat3 cov = t * sigma * t.transposed();
  const double det0 = cov(0, 0) * cov(1, 1) - cov(0, 1) * cov(1, 0);
  // Mip-Splatting's 2D filter, or 3DGS's dilation without opacity compensation.
  const double h = s.antialiased ? 0.1 : 0.3;
  const double a = cov(0, 0) + h, b = cov(0, 1), c = cov(1, 1) + h;
  const double det1 = a * c - b * b;
  if (!(det1 > 0)) return false;
  out.x = k.fx * v.x / v.z + k.cx;
  out.y = k.fy * v.y / v.z + k.cy;
  out.depth = v.z;
  out.opacity = 1 / (1 + std::exp(-s.opacity_logits[i])) * std::sqrt(ratio3d) *
                (s.antialiased ? std::sqrt(std::max(0.000025, det0 / det1)) : 1.0);
  out.conic[0] = c / det1;
  out.conic[1] = -b / det1;
  out.conic[2] = a / det1;
  Vec3 dir = mean - cam.center();
  dir = dir * (1 / dir.norm());
  for (int ch = 0; ch < 3; ++ch)
    out.color[ch] = sh_channel(s.sh_degree, &s.sh_dc[3 * i], &s.sh_rest[45 * i], ch, dir);
  return true;
}

inline ReferenceImage reference_render(const Scene<double>& s, const Camera& cam,
                                       const double background[3]) {
  std::vector<ReferenceSplat> splats;
  for (int i = 0; i < s.count(); ++i) {
    ReferenceSplat r;
    if (reference_project(s, i, cam, r)) splats.push_back(r);
  }
  std::stable_sort(
      splats.begin(), splats.end(),
      [](const ReferenceSplat& a, const ReferenceSplat& b) { return a.depth < b.depth; });
  ReferenceImage out;
  out.width = cam.intrinsics.width;
  out.height = cam.intrinsics.height;
  const size_t plane = size_t(out.width) * out.height;
  out.image.assign(3 * plane, 0);
  out.alpha.assign(plane, 0);
  out.depth.assign(plane, 0);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      double t = 1, rgb[3] = {0, 0, 0}, depth = 0;
      for (const ReferenceSplat& r : splats) {
        const double dx = r.x - (x + 0.5), dy = r.y - (y + 0.5);
        const double power =
            -0.5 * (r.conic[0] * dx * dx + r.conic[2] * dy * dy) - r.conic[1] * dx * dy;
        if (power > 0) continue;
        const double alpha = std::min(kAlphaCap, r.opacity * std::exp(power));
        if (alpha < kAlphaSkip) continue;
        if (t * (1 - alpha) < kTransmittanceStop) break;
        for (int c = 0; c < 3; ++c) rgb[c] += r.color[c] * alpha * t;
        depth += r.depth * alpha * t;
        t *= 1 - alpha;
      }
      const size_t i = size_t(y) * out.width + x;
      for (int c = 0; c < 3; ++c) out.image[c * plane + i] = rgb[c] + t * background[c];
      out.alpha[i] = 1 - t;
      out.depth[i] = depth;
    }
  return out;
}

}  // namespace iesrgs::raster::testkit
