#pragma once
// SIMD packs for the CPU pixel loops, with GCC / Clang vector extensions: the compilers do not
// auto-vectorize the blending loops (their selects defeat if-conversion). Packs are as wide as
// the compilation's vector unit: 16 bytes (SSE2, the baseline of portable x86-64 builds: four
// float lanes), 32 bytes where it targets AVX2 (the AVX2 variant, or -DIESRGS_NATIVE=ON on such a
// machine). Double packs let the same kernels run in double for the gradient checks. Everything
// here depends on the width, hence lives in the variant's namespace (core/cpu_isa_variant.hpp).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "core/cpu_isa_variant.hpp"
#include "raster/blend_math.hpp"

namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE {

#if defined(__AVX2__)
constexpr int kPackBytes = 32;
#else
constexpr int kPackBytes = 16;
#endif

template <typename T>
constexpr int kLanes = kPackBytes / sizeof(T);

template <typename T>
struct PackTypes;

template <>
struct PackTypes<float> {
  typedef float Pack __attribute__((vector_size(kPackBytes)));
  typedef int32_t Mask __attribute__((vector_size(kPackBytes)));    // comparison results: 0 or -1
  typedef uint32_t Index __attribute__((vector_size(kPackBytes)));  // unsigned lanes of mask width
};

template <>
struct PackTypes<double> {
  typedef double Pack __attribute__((vector_size(kPackBytes)));
  typedef int64_t Mask __attribute__((vector_size(kPackBytes)));
  typedef uint64_t Index __attribute__((vector_size(kPackBytes)));
};

// 32-bit lanes as stored in the pixel state, one per pack lane.
template <typename T>
struct StoredIndex {
  typedef uint32_t Type __attribute__((vector_size(4 * kLanes<T>)));
};

template <typename T>
using Pack = typename PackTypes<T>::Pack;
template <typename T>
using Mask = typename PackTypes<T>::Mask;
template <typename T>
using Index = typename PackTypes<T>::Index;

template <typename T>
inline Pack<T> load(const T* p) {
  Pack<T> v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

template <typename T>
inline void store(T* p, Pack<T> v) {
  std::memcpy(p, &v, sizeof v);
}

template <typename T>
inline Index<T> load_index(const uint32_t* p) {
  typename StoredIndex<T>::Type v;
  std::memcpy(&v, p, sizeof v);
  return __builtin_convertvector(v, Index<T>);
}

template <typename T>
inline void store_index(uint32_t* p, Index<T> v) {
  const auto narrow = __builtin_convertvector(v, typename StoredIndex<T>::Type);
  std::memcpy(p, &narrow, sizeof narrow);
}

template <typename T>
inline Pack<T> broadcast(T x) {
  return Pack<T>{} + x;
}

template <typename T>
inline Pack<T> select(Mask<T> m, Pack<T> a, Pack<T> b) {
  return m ? a : b;
}

template <typename T>
inline T horizontal_sum(Pack<T> v) {
  T sum = 0;
  for (int i = 0; i < kLanes<T>; ++i) sum += v[i];
  return sum;
}

// sums[k] = horizontal_sum(v[k]) for each of the N packs. With AVX, eight float packs at a time
// through a transposing tree of horizontal adds: a dozen instructions where lane-by-lane sums
// take about ten each.
template <typename T, int N>
inline void horizontal_sums(const Pack<T> (&v)[N], T* sums) {
#if defined(__AVX__)
  if constexpr (std::is_same_v<T, float> && kLanes<T> == 8) {
    for (int k = 0; k < N; k += 8) {
      __m256 p[8];
      for (int j = 0; j < 8; ++j) p[j] = k + j < N ? (__m256)v[k + j] : _mm256_setzero_ps();
      // Pairs, then quads of lanes summed per pack: ab holds the four-lane sums of packs 0..3 in
      // its low half (lanes 0..3) and of the same packs' lanes 4..7 in its high half.
      const __m256 ab = _mm256_hadd_ps(_mm256_hadd_ps(p[0], p[1]), _mm256_hadd_ps(p[2], p[3]));
      const __m256 cd = _mm256_hadd_ps(_mm256_hadd_ps(p[4], p[5]), _mm256_hadd_ps(p[6], p[7]));
      const __m256 total =
          _mm256_add_ps(_mm256_permute2f128_ps(ab, cd, 0x20), _mm256_permute2f128_ps(ab, cd, 0x31));
      float out[8];
      _mm256_storeu_ps(out, total);
      std::memcpy(sums + k, out, sizeof(float) * std::min(8, N - k));
    }
    return;
  }
#endif
  for (int k = 0; k < N; ++k) sums[k] = horizontal_sum<T>(v[k]);
}

// Number of set lanes of a comparison mask: the sign bits gathered by one instruction where
// there is one (a lane-by-lane loop extracts each lane, a sixth of the forward blend's time).
template <typename T>
inline int count(Mask<T> m) {
#if defined(__AVX__)
  if constexpr (kPackBytes == 32)
    return __builtin_popcount(sizeof(T) == 4 ? _mm256_movemask_ps((__m256)m)
                                             : _mm256_movemask_pd((__m256d)m));
#endif
#if defined(__SSE2__)
  if constexpr (kPackBytes == 16)
    return __builtin_popcount(sizeof(T) == 4 ? _mm_movemask_ps((__m128)m)
                                             : _mm_movemask_pd((__m128d)m));
#endif
  int n = 0;
  for (int i = 0; i < kLanes<T>; ++i) n -= int(m[i]);  // set lanes are -1
  return n;
}

template <typename T>
inline Pack<T> abs(Pack<T> v) {
  return select<T>(v < T(0), -v, v);
}

// falloff_exp lane by lane. In float a Cephes-style polynomial (relative error about 2e-7, far
// below 8-bit output) instead of the libm call; both passes use it, so they see the same alphas.
template <typename T>
inline Pack<T> falloff_exp(Pack<T> x) {
  Pack<T> r;
  for (int i = 0; i < kLanes<T>; ++i) r[i] = raster::falloff_exp(x[i]);
  return r;
}

template <>
inline Pack<float> falloff_exp<float>(Pack<float> x) {
  typedef int32_t I32 __attribute__((vector_size(kPackBytes)));
  x = select<float>(x < -87.f, broadcast(-87.f), x);  // 2^n stays a normal float
  x = select<float>(x > 0.f, Pack<float>{}, x);
  // x = n ln2 + r with |r| <= ln2 / 2; adding and removing 1.5 * 2^23 rounds to the nearest
  // integer.
  const Pack<float> n = (x * 1.44269504f + 12582912.f) - 12582912.f;
  const Pack<float> r = (x - n * 0.693359375f) + n * 2.12194440e-4f;
  const Pack<float> p = ((((((1.9875691500e-4f * r + 1.3981999507e-3f) * r + 8.3334519073e-3f) * r +
                            4.1665795894e-2f) *
                               r +
                           1.6666665459e-1f) *
                              r +
                          5.0000001201e-1f) *
                         r * r) +
                        r + 1.f;
  const I32 bits = (__builtin_convertvector(n, I32) + 127) << 23;
  Pack<float> scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

// splat_alpha on a pack: min(0.99, weight), zero where skipped.
template <typename T>
inline Pack<T> splat_alpha(Pack<T> power, Pack<T> weight) {
  const Pack<T> alpha = select<T>(weight < T(kMaxAlpha), weight, broadcast(T(kMaxAlpha)));
  return select<T>((alpha < T(kMinAlpha)) | (power > T(0)), Pack<T>{}, alpha);
}

}  // namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE
