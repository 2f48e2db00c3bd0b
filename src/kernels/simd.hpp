// SIMD lanes for the element kernel (fe_forces.hpp): the per-element arithmetic is written once,
// as a template on its number type T, and instantiated with T = double (one element: GPUs, and
// the odd element at the end of a CPU range) and with T = Double8 (eight elements at once in
// one AVX-512 register, GCC vector extensions). The same source then serves both: arithmetic,
// comparisons, !, &&, || and ?: act lane by lane on Double8 (GCC, "Using Vector Instructions
// through Built-in Functions"), so element code must avoid `if` on per-element values and
// write a select (c ? a : b) instead. Compilers do not vectorize the element kernel by themselves
// (its lane loop holds inner loops and branches; GCC 12 gives up), hence the explicit type.
#pragma once
#include "kernels/compat.hpp"

#if !defined(KOKKOS_ENABLE_CUDA) && !defined(KOKKOS_ENABLE_HIP) && !defined(KOKKOS_ENABLE_SYCL) && \
    defined(__GNUC__)
#define FRACTA_HOST_SIMD 1
#if defined(__AVX512F__)
#include <immintrin.h>
#endif
#endif

namespace fracta {

// A value of T with every lane x.
template <class T>
KOKKOS_INLINE_FUNCTION T splat(double x) {
  return T{} + x;
}

KOKKOS_INLINE_FUNCTION double get_lane(double v, int) {
  return v;
}
KOKKOS_INLINE_FUNCTION void set_lane(double& v, int, double x) {
  v = x;
}
KOKKOS_INLINE_FUNCTION bool get_lane(bool m, int) {
  return m;
}
KOKKOS_INLINE_FUNCTION bool any_lane(bool m) {
  return m;
}

template <class T>
struct LaneCount {
  static constexpr int value = 1;
};

#ifdef FRACTA_HOST_SIMD
typedef double Double8 __attribute__((vector_size(64)));
typedef long Mask8 __attribute__((vector_size(64)));  // a comparison's result: 0 or -1 per lane

template <>
struct LaneCount<Double8> {
  static constexpr int value = 8;
};

inline double get_lane(const Double8& v, int l) {
  return v[l];
}
inline void set_lane(Double8& v, int l, double x) {
  v[l] = x;
}
inline bool get_lane(const Mask8& m, int l) {
  return m[l] != 0;
}
inline bool any_lane(const Mask8& m) {
  long r = 0;
  for (int l = 0; l < 8; ++l) r |= m[l];
  return r != 0;
}
inline Double8 sqrt_(Double8 a) {
#if defined(__AVX512F__)
  // The masked form with every lane set: _mm512_sqrt_pd's undefined pass-through operand
  // trips GCC 12's -Wuninitialized.
  return _mm512_mask_sqrt_pd(a, static_cast<__mmask8>(0xFF), a);
#else
  for (int l = 0; l < 8; ++l) a[l] = sqrt_(a[l]);
  return a;
#endif
}

// Elements per work item of the element kernel on this build.
inline constexpr int kLanes = 8;
using LaneDouble = Double8;
#else
inline constexpr int kLanes = 1;
using LaneDouble = double;
#endif

}  // namespace fracta
