// Per-Gaussian projection, forward and backward, parallel over Gaussians. In float, a pack of
// Gaussians goes through the formulas of raster/project.hpp at once, one per SIMD lane
// (lanes.hpp), with the results of the scalar code to the bit; double, for the gradient checks,
// runs them one Gaussian at a time. Compiled once per instruction-set variant (isa.hpp), each into
// its own namespace, and without fused multiply-adds (CMakeLists.txt).
#include <algorithm>
#include <cstring>

#include "raster/cpu/lanes.hpp"
#include "raster/cpu/variants.hpp"
#include "raster/project.hpp"

namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE {

namespace {

constexpr int kShFloats = 3 * gs::kShCoefficients;

// Number of fields of a struct made of T only (Splat, SplatGrad, Sym2, GaussianRowGrad).
template <template <typename> class Struct>
constexpr int field_count() {
  constexpr int n = sizeof(Struct<float>) / sizeof(float);
  static_assert(sizeof(Struct<float>) == n * sizeof(float));
  static_assert(sizeof(Struct<FloatLanes>) == n * sizeof(FloatLanes));
  return n;
}

// The struct whose lane l holds *rows[l].
template <template <typename> class Struct>
Struct<FloatLanes> gather(const Struct<float>* const* rows) {
  constexpr int n = field_count<Struct>();
  FloatLanes fields[n];
  for (int l = 0; l < kFloatLanes; ++l) {
    float row[n];
    std::memcpy(row, rows[l], sizeof row);
    for (int f = 0; f < n; ++f) fields[f].v[l] = row[f];
  }
  Struct<FloatLanes> packed;
  std::memcpy(&packed, fields, sizeof packed);
  return packed;
}

// rows[l] = lane l of packed.
template <template <typename> class Struct>
void scatter(const Struct<FloatLanes>& packed, Struct<float>* rows) {
  constexpr int n = field_count<Struct>();
  FloatLanes fields[n];
  std::memcpy(fields, &packed, sizeof fields);
  for (int l = 0; l < kFloatLanes; ++l) {
    float row[n];
    for (int f = 0; f < n; ++f) row[f] = fields[f].v[l];
    std::memcpy(&rows[l], row, sizeof row);
  }
}

RasterCamera<FloatLanes> lanes_camera(const RasterCamera<float>& cam) {
  RasterCamera<FloatLanes> c;
  c.width = cam.width;
  c.height = cam.height;
  c.fx = cam.fx;
  c.fy = cam.fy;
  c.cx = cam.cx;
  c.cy = cam.cy;
  for (int k = 0; k < 9; ++k) c.rotation[k] = cam.rotation[k];
  for (int k = 0; k < 3; ++k) c.translation[k] = cam.translation[k];
  return c;
}

// Gaussians index[0..kFloatLanes) of g, one per lane; only the active SH bands are read.
struct RowLanes {
  FloatLanes mean[3], log_scale[3], quat[4], opacity_logit, filter_std, sh[kShFloats];
  int sh_degree;
  bool antialiased;

  RowLanes(const GaussianParams<float>& g, const int* index)
      : sh_degree(g.sh_degree), antialiased(g.antialiased) {
    const int sh_floats = 3 * gs::sh_count(g.sh_degree);
    for (int l = 0; l < kFloatLanes; ++l) {
      const int i = index[l];
      for (int k = 0; k < 3; ++k) mean[k].v[l] = g.means[3 * i + k];
      for (int k = 0; k < 3; ++k) log_scale[k].v[l] = g.log_scales[3 * i + k];
      for (int k = 0; k < 4; ++k) quat[k].v[l] = g.quats[4 * i + k];
      opacity_logit.v[l] = g.opacity_logits[i];
      filter_std.v[l] = g.filter_std ? g.filter_std[i] : 0.f;
      for (int k = 0; k < sh_floats; ++k) sh[k].v[l] = g.sh[kShFloats * i + k];
    }
  }

  GaussianRow<FloatLanes> row() const {
    return {{mean[0], mean[1], mean[2]},
            log_scale,
            quat,
            opacity_logit,
            filter_std,
            sh,
            sh_degree,
            antialiased};
  }
};

// Lane indices for Gaussians first..first + kFloatLanes, the last one repeated past count.
void lane_indices(int first, int count, int* index) {
  for (int l = 0; l < kFloatLanes; ++l) index[l] = first + l < count ? first + l : count - 1;
}

void forward_lanes(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                   Splat<float>* splats, PixelRect* rects, int32_t* radii) {
  const RasterCamera<FloatLanes> lanes_cam = lanes_camera(cam);
  const int packs = (g.count + kFloatLanes - 1) / kFloatLanes;
#pragma omp parallel for schedule(static)
  for (int pack = 0; pack < packs; ++pack) {
    const int first = pack * kFloatLanes;
    int index[kFloatLanes];
    lane_indices(first, g.count, index);
    const RowLanes in(g, index);
    const GaussianRow<FloatLanes> row = in.row();
    Projection<FloatLanes> p;
    const LaneMask visible = project(row, lanes_cam, p);
    Splat<float> splat[kFloatLanes];
    Sym2<float> filtered[kFloatLanes];
    scatter<Splat>(make_splat(row, lanes_cam, p), splat);
    scatter<Sym2>(p.filtered, filtered);
    for (int l = 0; l < kFloatLanes && first + l < g.count; ++l) {
      const int i = first + l;
      rects[i] = {0, 0, 0, 0};
      radii[i] = 0;
      if (!visible[l]) continue;
      splats[i] = splat[l];
      rects[i] = splat_rect(splat[l], filtered[l], cam.width, cam.height);
      if (!rects[i].empty()) radii[i] = splat_radius(splat[l], filtered[l]);
    }
  }
}

// Gaussians per block of the backward pass, whose ones with a gradient are packed into lanes.
constexpr int kBackwardBlock = 256;

void backward_pack(const GaussianParams<float>& g, const RasterCamera<FloatLanes>& cam,
                   const SplatGrad<float>* splat_grads, const int* index, int used,
                   const GaussianGrads<float>& grads) {
  const SplatGrad<float>* rows[kFloatLanes];
  for (int l = 0; l < kFloatLanes; ++l) rows[l] = &splat_grads[index[l]];
  const RowLanes in(g, index);
  GaussianRowGrad<FloatLanes> d;
  const LaneMask visible = project_backward(in.row(), cam, gather<SplatGrad>(rows), d);
  GaussianRowGrad<float> lane_grads[kFloatLanes];
  scatter<GaussianRowGrad>(d, lane_grads);
  for (int l = 0; l < used; ++l)
    if (visible[l]) add_row_grad(lane_grads[l], index[l], grads);
}

// A Gaussian outside the view, or hidden behind others wherever it falls, has all-zero partials
// and contributes nothing: skipping it saves recomputing its projection (most of the backward
// pass on small images, where many Gaussians are hidden).
void backward_lanes(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                    const SplatGrad<float>* splat_grads, const GaussianGrads<float>& grads) {
  const RasterCamera<FloatLanes> lanes_cam = lanes_camera(cam);
  const int blocks = (g.count + kBackwardBlock - 1) / kBackwardBlock;
#pragma omp parallel for schedule(static)
  for (int block = 0; block < blocks; ++block) {
    int live[kBackwardBlock + kFloatLanes];
    int n = 0;
    const int end = std::min(g.count, (block + 1) * kBackwardBlock);
    for (int i = block * kBackwardBlock; i < end; ++i)
      if (!splat_grads[i].is_zero()) live[n++] = i;
    for (int start = 0; start < n; start += kFloatLanes) {
      const int used = std::min(kFloatLanes, n - start);
      for (int l = used; l < kFloatLanes; ++l) live[start + l] = live[start + used - 1];
      backward_pack(g, lanes_cam, splat_grads, live + start, used, grads);
    }
  }
}

#if !defined(IESRGS_CPU_ISA_AVX2)
void forward_rows(const GaussianParams<double>& g, const RasterCamera<double>& cam,
                  Splat<double>* splats, PixelRect* rects, int32_t* radii) {
#pragma omp parallel for schedule(static)
  for (int i = 0; i < g.count; ++i) {
    Projection<double> p;
    rects[i] = {0, 0, 0, 0};
    radii[i] = 0;
    if (!project(g, i, cam, p)) continue;
    splats[i] = make_splat(g, i, cam, p);
    rects[i] = splat_rect(splats[i], p.filtered, cam.width, cam.height);
    if (!rects[i].empty()) radii[i] = splat_radius(splats[i], p.filtered);
  }
}

void backward_rows(const GaussianParams<double>& g, const RasterCamera<double>& cam,
                   const SplatGrad<double>* splat_grads, const GaussianGrads<double>& grads) {
#pragma omp parallel for schedule(static)
  for (int i = 0; i < g.count; ++i)
    if (!splat_grads[i].is_zero()) project_backward(g, i, cam, splat_grads[i], grads);
}
#endif

}  // namespace

template <>
ProjectPasses<float> project_passes() {
  return {forward_lanes, backward_lanes};
}

// Double gets no SIMD variant: the baseline's scalar code checks the gradients.
#if !defined(IESRGS_CPU_ISA_AVX2)
template <>
ProjectPasses<double> project_passes() {
  return {forward_rows, backward_rows};
}
#endif

}  // namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE
