// The projection of a pack of Gaussians at once, one per SIMD lane: the formulas of
// raster/project.hpp on FloatLanes (lanes.hpp), with the results of the scalar code to the bit.
// Compiled once per instruction-set variant (core/cpu_isa_variant.hpp), each into its own
// namespace, and without fused multiply-adds (CMakeLists.txt); project.cpp runs the loops around
// it.
#include <cstring>

#include "raster/cpu/lanes.hpp"
#include "raster/cpu/variants.hpp"

namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE {

namespace {

// Number of fields of a struct made of T only (Splat, SplatGrad, SplatBounds, GaussianRowGrad).
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

void scatter_mask(LaneMask mask, bool* lanes) {
  for (int l = 0; l < kFloatLanes; ++l) lanes[l] = mask[l];
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
  FloatLanes mean[3], log_scale[3], quat[4], opacity_logit, filter_std, sh_dc[3],
      sh_rest[gs::kShRestFloats];
  int sh_degree;
  bool antialiased;

  RowLanes(const GaussianParams<float>& g, const int* index)
      : sh_degree(g.sh_degree), antialiased(g.antialiased) {
    const int rest_floats = 3 * (gs::sh_count(g.sh_degree) - 1);
    for (int l = 0; l < kFloatLanes; ++l) {
      const int i = index[l];
      for (int k = 0; k < 3; ++k) mean[k].v[l] = g.means[3 * i + k];
      for (int k = 0; k < 3; ++k) log_scale[k].v[l] = g.log_scales[3 * i + k];
      for (int k = 0; k < 4; ++k) quat[k].v[l] = g.quats[4 * i + k];
      opacity_logit.v[l] = g.opacity_logits[i];
      filter_std.v[l] = g.filter_std ? g.filter_std[i] : 0.f;
      for (int k = 0; k < 3; ++k) sh_dc[k].v[l] = g.sh_dc[3 * i + k];
      for (int k = 0; k < rest_floats; ++k)
        sh_rest[k].v[l] = g.sh_rest[gs::kShRestFloats * size_t(i) + k];
    }
  }

  GaussianRow<FloatLanes> row() const {
    return {{mean[0], mean[1], mean[2]},
            log_scale,
            quat,
            opacity_logit,
            filter_std,
            {sh_dc, sh_rest},
            sh_degree,
            antialiased};
  }
};

void forward_pack(const GaussianParams<float>& g, const RasterCamera<float>& cam, const int* index,
                  Splat<float>* splats, SplatBounds<float>* bounds, bool* visible) {
  const RasterCamera<FloatLanes> lanes_cam = lanes_camera(cam);
  const RowLanes in(g, index);
  const GaussianRow<FloatLanes> row = in.row();
  Projection<FloatLanes> p;
  scatter_mask(project(row, lanes_cam, p), visible);
  const Splat<FloatLanes> splat = make_splat(row, lanes_cam, p);
  SplatBounds<FloatLanes> b;
  splat_bounds(splat, p.filtered, cam.width, cam.height, b);
  scatter<Splat>(splat, splats);
  scatter<SplatBounds>(b, bounds);
}

void backward_pack(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                   const SplatGrad<float>* splat_grads, const int* index,
                   GaussianRowGrad<float>* grads, bool* visible) {
  const SplatGrad<float>* rows[kFloatLanes];
  for (int l = 0; l < kFloatLanes; ++l) rows[l] = &splat_grads[index[l]];
  const RowLanes in(g, index);
  GaussianRowGrad<FloatLanes> d;
  scatter_mask(project_backward(in.row(), lanes_camera(cam), gather<SplatGrad>(rows), d), visible);
  scatter<GaussianRowGrad>(d, grads);
}

}  // namespace

ProjectPacks project_packs() {
  return {forward_pack, backward_pack, kFloatLanes};
}

}  // namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE
