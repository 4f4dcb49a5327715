#pragma once
// Floats in SIMD lanes that the scalar formulas of raster/project.hpp accept as their T, so that
// the CPU projection runs them on a pack of Gaussians at once, one per lane. Every operation rounds
// as the scalar one does: arithmetic, sqrt, ceil and floor are exact IEEE operations on each lane,
// exp and log call the C library lane by lane, min, max and select keep the scalar NaN behavior,
// and the variant that includes this compiles without contracting into fused multiply-adds. The
// lanes give the scalar code's results to the bit.
#include <cmath>

#include "core/hd.hpp"
#include "raster/cpu/pack.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE {

constexpr int kFloatLanes = kLanes<float>;

// The result of comparing lanes: all bits set where it holds.
struct LaneMask {
  Mask<float> bits;

  bool operator[](int lane) const { return bits[lane] != 0; }
  friend LaneMask operator&&(LaneMask a, LaneMask b) { return {a.bits & b.bits}; }
  friend LaneMask operator||(LaneMask a, LaneMask b) { return {a.bits | b.bits}; }
};

struct FloatLanes {
  Pack<float> v;

  FloatLanes() = default;
  FloatLanes(float x) : v(broadcast(x)) {}  // NOLINT: constants in the formulas broadcast
  explicit FloatLanes(Pack<float> p) : v(p) {}

  friend FloatLanes operator+(FloatLanes a, FloatLanes b) { return FloatLanes(a.v + b.v); }
  friend FloatLanes operator-(FloatLanes a, FloatLanes b) { return FloatLanes(a.v - b.v); }
  friend FloatLanes operator*(FloatLanes a, FloatLanes b) { return FloatLanes(a.v * b.v); }
  friend FloatLanes operator/(FloatLanes a, FloatLanes b) { return FloatLanes(a.v / b.v); }
  friend FloatLanes operator-(FloatLanes a) { return FloatLanes(-a.v); }
  FloatLanes& operator+=(FloatLanes b) { return *this = *this + b; }
  FloatLanes& operator-=(FloatLanes b) { return *this = *this - b; }
  FloatLanes& operator*=(FloatLanes b) { return *this = *this * b; }
  friend LaneMask operator<(FloatLanes a, FloatLanes b) { return {a.v < b.v}; }
  friend LaneMask operator>(FloatLanes a, FloatLanes b) { return {a.v > b.v}; }
  friend LaneMask operator<=(FloatLanes a, FloatLanes b) { return {a.v <= b.v}; }
};

inline FloatLanes lanewise_select(LaneMask m, FloatLanes a, FloatLanes b) {
  return FloatLanes(select<float>(m.bits, a.v, b.v));
}

template <typename Function>
inline FloatLanes each_lane(FloatLanes x, Function f) {
  for (int i = 0; i < kFloatLanes; ++i) x.v[i] = f(x.v[i]);
  return x;
}

// ceil (up) or floor of every lane: one instruction with AVX, the C library's per lane without.
template <bool kUp>
inline FloatLanes round_lanes(FloatLanes x) {
#if defined(__AVX__)
  constexpr int kMode = (kUp ? _MM_FROUND_TO_POS_INF : _MM_FROUND_TO_NEG_INF) | _MM_FROUND_NO_EXC;
  return FloatLanes((Pack<float>)_mm256_round_ps((__m256)x.v, kMode));
#else
  return each_lane(x, [](float a) { return kUp ? std::ceil(a) : std::floor(a); });
#endif
}

}  // namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE

namespace iesrgs::hd {

using raster::cpu::IESRGS_CPU_ISA_NAMESPACE::FloatLanes;
using raster::cpu::IESRGS_CPU_ISA_NAMESPACE::LaneMask;
using raster::cpu::IESRGS_CPU_ISA_NAMESPACE::round_lanes;

template <>
inline FloatLanes select<FloatLanes>(LaneMask cond, FloatLanes a, FloatLanes b) {
  return lanewise_select(cond, a, b);
}
template <>
inline FloatLanes min<FloatLanes>(FloatLanes a, FloatLanes b) {
  return lanewise_select(b < a, b, a);
}
template <>
inline FloatLanes max<FloatLanes>(FloatLanes a, FloatLanes b) {
  return lanewise_select(a < b, b, a);
}
template <>
inline FloatLanes sqrt<FloatLanes>(FloatLanes x) {
#if defined(__AVX__)
  return FloatLanes(
      (raster::cpu::IESRGS_CPU_ISA_NAMESPACE::Pack<float>)_mm256_sqrt_ps((__m256)x.v));
#elif defined(__SSE2__)
  return FloatLanes((raster::cpu::IESRGS_CPU_ISA_NAMESPACE::Pack<float>)_mm_sqrt_ps((__m128)x.v));
#else
  return each_lane(x, [](float a) { return std::sqrt(a); });
#endif
}
template <>
inline FloatLanes ceil<FloatLanes>(FloatLanes x) {
  return round_lanes<true>(x);
}
template <>
inline FloatLanes floor<FloatLanes>(FloatLanes x) {
  return round_lanes<false>(x);
}
template <>
inline FloatLanes exp<FloatLanes>(FloatLanes x) {
  return each_lane(x, [](float a) { return std::exp(a); });
}
template <>
inline FloatLanes log<FloatLanes>(FloatLanes x) {
  return each_lane(x, [](float a) { return std::log(a); });
}

}  // namespace iesrgs::hd
