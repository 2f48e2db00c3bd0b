// SIMD lanes for the element kernel (fe_forces.hpp): the per-element arithmetic is written once,
// as a template on its number type T, and instantiated with T = double (one element: GPUs, and
// the odd element at the end of a CPU range) and with T = Double8 (eight elements at once in
// one AVX-512 register, GCC vector extensions). The same source then serves both: arithmetic,
// comparisons, !, &&, || and ?: act lane by lane on Double8 (GCC, "Using Vector Instructions
// through Built-in Functions"), so element code must avoid `if` on per-element values and
// write a select (c ? a : b) instead. Compilers do not vectorize the element kernel by themselves
// (its lane loop holds inner loops and branches; GCC 12 gives up), hence the explicit type.
#pragma once
#include <type_traits>

#include "kernels/compat.hpp"

#if !defined(FRACTA_DEVICE_PATH) && defined(__GNUC__)
#define FRACTA_HOST_SIMD 1
#if defined(__AVX__)
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

// A comparison result that is true in every lane (bool for double).
template <class T>
KOKKOS_INLINE_FUNCTION auto all_lanes() {
  return splat<T>(0.0) == 0.0;
}

// The corners (counter-clockwise) of L quads lie along one row of a structured mesh: corner 0 of
// lane l at node n0 + l, corner 1 at n0 + l + 1, corner 3 at m0 + l, corner 2 at m0 + l + 1. Their
// node data then comes by vector loads (load_pairs) instead of gathers.
template <int L>
KOKKOS_FORCEINLINE_FUNCTION bool structured_row(const int (&node)[4][L]) {
  bool row = true;
  for (int l = 0; l < L; ++l)
    row = row && node[0][l] == node[0][0] + l && node[1][l] == node[0][l] + 1 &&
          node[3][l] == node[3][0] + l && node[2][l] == node[3][l] + 1;
  return row;
}

template <class T>
struct LaneCount {
  static constexpr int value = 1;
};

// Lane l of v from column[index[l]] (a per-item array: a 1D view's data, or one component's
// column of a LayoutLeft view), and back. With consecutive (index[l] = index[0] + l) the lanes
// move as one vector load or store.
template <class T, int L>
KOKKOS_INLINE_FUNCTION T load_lanes(const double* column, const int (&index)[L], bool consecutive);
template <class T, int L>
KOKKOS_INLINE_FUNCTION void store_lanes(const T& v, double* column, const int (&index)[L],
                                        bool consecutive);

// Lane l of v from base[index[l] * stride] (e.g. one coordinate of a LayoutRight node array).
template <class T, int L>
KOKKOS_INLINE_FUNCTION T gather_lanes(const double* base, const int (&index)[L], int stride);
template <>
KOKKOS_INLINE_FUNCTION double gather_lanes<double, 1>(const double* base, const int (&index)[1],
                                                      int stride) {
  return base[index[0] * stride];
}

template <>
KOKKOS_INLINE_FUNCTION double load_lanes<double, 1>(const double* column, const int (&index)[1],
                                                    bool) {
  return column[index[0]];
}
template <>
KOKKOS_INLINE_FUNCTION void store_lanes<double, 1>(const double& v, double* column,
                                                   const int (&index)[1], bool) {
  column[index[0]] = v;
}

// The scalar forms of load_triple_lanes and store_triple_lanes (one row).
KOKKOS_INLINE_FUNCTION void load_triple_lanes(const double* base, const int (&index)[1],
                                              double (&v)[3]) {
  for (int c = 0; c < 3; ++c) v[c] = base[3 * index[0] + c];
}
KOKKOS_INLINE_FUNCTION void store_triple_lanes(double* base, const int (&index)[1],
                                               const double (&v)[3]) {
  for (int c = 0; c < 3; ++c) base[3 * index[0] + c] = v[c];
}

// column[index[l]] += lane l of v.
template <class T, int L>
KOKKOS_INLINE_FUNCTION void add_lanes(const T& v, double* column, const int (&index)[L],
                                      bool consecutive) {
  store_lanes(load_lanes<T>(column, index, consecutive) + v, column, index, consecutive);
}

#ifdef FRACTA_HOST_SIMD
// Eight lanes (one AVX-512 register; two AVX ones) and four (one AVX register). The element
// kernel and the kicks take the machine's own width (NativeDouble, below); the bond kernel takes
// eight. The helpers are forced inline: GCC's inliner gives up on some of them inside the large
// element kernel, and a call per load took 4 % of the main job's step (perf, AVX2).
typedef double Double8 __attribute__((vector_size(64)));
typedef long Mask8 __attribute__((vector_size(64)));  // a comparison's result: 0 or -1 per lane
typedef double Double4 __attribute__((vector_size(32)));
typedef long Mask4 __attribute__((vector_size(32)));

template <>
struct LaneCount<Double8> {
  static constexpr int value = 8;
};
template <>
struct LaneCount<Double4> {
  static constexpr int value = 4;
};

// The lane types and their comparison masks, for the helpers written once for both widths.
template <class V>
using if_lanes = typename std::enable_if<(LaneCount<V>::value > 1), int>::type;
template <class M>
using if_lane_mask =
    typename std::enable_if<std::is_same<M, Mask8>::value || std::is_same<M, Mask4>::value,
                            int>::type;

template <class V, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION double get_lane(const V& v, int l) {
  return v[l];
}
template <class V, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION void set_lane(V& v, int l, double x) {
  v[l] = x;
}
template <class M, if_lane_mask<M> = 0>
KOKKOS_FORCEINLINE_FUNCTION bool get_lane(const M& m, int l) {
  return m[l] != 0;
}
template <class M, if_lane_mask<M> = 0>
KOKKOS_FORCEINLINE_FUNCTION bool any_lane(const M& m) {
  long r = 0;
  for (int l = 0; l < static_cast<int>(sizeof(M) / sizeof(long)); ++l) r |= m[l];
  return r != 0;
}

namespace detail {
template <class V, int L>
KOKKOS_FORCEINLINE_FUNCTION void load_lanes(V& v, const double* column, const int (&index)[L],
                                            bool consecutive) {
  if (consecutive) {
    __builtin_memcpy(&v, column + index[0], sizeof v);
  } else {
    for (int l = 0; l < L; ++l) v[l] = column[index[l]];
  }
}
template <class V, int L>
KOKKOS_FORCEINLINE_FUNCTION void store_lanes(const V& v, double* column, const int (&index)[L],
                                             bool consecutive) {
  if (consecutive) {
    __builtin_memcpy(column + index[0], &v, sizeof v);
  } else {
    for (int l = 0; l < L; ++l) column[index[l]] = v[l];
  }
}
// Lane by lane from scalar loads: on the AMD EPYC (Zen 4) machines here this beats the AVX-512
// gather instruction (vgatherdpd), which the profile showed stalling the bond batches; measured
// on the bond phase (1e6 discs, 1 thread): 25 -> 32 M bond-steps/s.
template <class V, int L>
KOKKOS_FORCEINLINE_FUNCTION void gather_lanes(V& v, const double* base, const int (&index)[L],
                                              int stride) {
  for (int l = 0; l < L; ++l) v[l] = base[index[l] * stride];
}
}  // namespace detail

template <>
KOKKOS_FORCEINLINE_FUNCTION Double8 load_lanes<Double8, 8>(const double* column,
                                                           const int (&index)[8],
                                                           bool consecutive) {
  Double8 v;
  detail::load_lanes(v, column, index, consecutive);
  return v;
}
template <>
KOKKOS_FORCEINLINE_FUNCTION Double4 load_lanes<Double4, 4>(const double* column,
                                                           const int (&index)[4],
                                                           bool consecutive) {
  Double4 v;
  detail::load_lanes(v, column, index, consecutive);
  return v;
}
template <>
KOKKOS_FORCEINLINE_FUNCTION void store_lanes<Double8, 8>(const Double8& v, double* column,
                                                         const int (&index)[8], bool consecutive) {
  detail::store_lanes(v, column, index, consecutive);
}
template <>
KOKKOS_FORCEINLINE_FUNCTION void store_lanes<Double4, 4>(const Double4& v, double* column,
                                                         const int (&index)[4], bool consecutive) {
  detail::store_lanes(v, column, index, consecutive);
}
template <>
KOKKOS_FORCEINLINE_FUNCTION Double8 gather_lanes<Double8, 8>(const double* base,
                                                             const int (&index)[8], int stride) {
  Double8 v;
  detail::gather_lanes(v, base, index, stride);
  return v;
}
template <>
KOKKOS_FORCEINLINE_FUNCTION Double4 gather_lanes<Double4, 4>(const double* base,
                                                             const int (&index)[4], int stride) {
  Double4 v;
  detail::gather_lanes(v, base, index, stride);
  return v;
}

// The vector square root instruction (correctly rounded, as the scalar one: the same bits). Not
// lane by lane through the scalar sqrt_: GCC keeps that a call (it must set errno for a
// negative lane), which took 8 % of an AVX2 machine's main job.
KOKKOS_FORCEINLINE_FUNCTION Double4 sqrt_(Double4 a) {
#if defined(__AVX__)
  return reinterpret_cast<Double4>(_mm256_sqrt_pd(reinterpret_cast<__m256d>(a)));
#else
  for (int l = 0; l < 4; ++l) a[l] = sqrt_(a[l]);
  return a;
#endif
}
KOKKOS_FORCEINLINE_FUNCTION Double8 sqrt_(Double8 a) {
#if defined(__AVX512F__)
  // The masked form with every lane set: _mm512_sqrt_pd's undefined pass-through operand
  // trips GCC 12's -Wuninitialized.
  return _mm512_mask_sqrt_pd(a, static_cast<__mmask8>(0xFF), a);
#else
  const Double4 lo = sqrt_(Double4{a[0], a[1], a[2], a[3]});
  const Double4 hi = sqrt_(Double4{a[4], a[5], a[6], a[7]});
  return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
#endif
}

// Lane by lane through the scalar exp_ (the same result as the scalar code's, to the bit).
template <class V, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION V exp_(V a) {
  for (int l = 0; l < LaneCount<V>::value; ++l) a[l] = exp_(a[l]);
  return a;
}

// compat.hpp's fma_ lane by lane: the fused instruction where the machine has it.
KOKKOS_FORCEINLINE_FUNCTION Double4 fma_(const Double4& a, const Double4& b, const Double4& c) {
#if defined(__FMA__)
  return reinterpret_cast<Double4>(_mm256_fmadd_pd(
      reinterpret_cast<__m256d>(a), reinterpret_cast<__m256d>(b), reinterpret_cast<__m256d>(c)));
#else
  return a * b + c;
#endif
}
KOKKOS_FORCEINLINE_FUNCTION Double8 fma_(const Double8& a, const Double8& b, const Double8& c) {
#if defined(__AVX512F__)
  return reinterpret_cast<Double8>(_mm512_fmadd_pd(
      reinterpret_cast<__m512d>(a), reinterpret_cast<__m512d>(b), reinterpret_cast<__m512d>(c)));
#else
  // Lane by lane (a fused multiply-add is correctly rounded: the same bits as one instruction).
  Double8 r = a;
  for (int l = 0; l < 8; ++l) r[l] = fma_(a[l], b[l], c[l]);
  return r;
#endif
}

// log10 of the lanes, without a call per lane: x = m 2^e with m in [sqrt(1/2), sqrt(2)), then
// ln m = 2 atanh(s) = 2 (s + s^3 / 3 + s^5 / 5 + ...), s = (m - 1) / (m + 1), |s| <= 0.1716,
// whose terms to s^25 leave less than 1e-19; ln 2 in two parts. Within 4 ulps of the scalar
// log10_ (tested) for positive finite lanes; a zero, negative, NaN or subnormal lane gives some
// number, which callers select away (RateLaw::factor).
template <class V, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION V log10_(const V& x) {
  using M = decltype(x < 0.0);
  M bits;
  __builtin_memcpy(&bits, &x, sizeof bits);
  const M exponent = ((bits >> 52) & 0x7ff) - 1023;
  const M mantissa_bits = (bits & 0x000fffffffffffffL) | 0x3ff0000000000000L;
  V m;  // in [1, 2)
  __builtin_memcpy(&m, &mantissa_bits, sizeof m);
  V e = __builtin_convertvector(exponent, V);
  const M above = m > 1.4142135623730951;
  m = above ? 0.5 * m : m;
  e = above ? e + 1.0 : e;
  const V s = (m - 1.0) / (m + 1.0), s2 = s * s;
  V series = 1.0 / 25.0 + splat<V>(0.0);
  for (int k = 11; k >= 0; --k) series = 1.0 / (2 * k + 1) + s2 * series;
  constexpr double ln2_hi = 6.93147180369123816490e-01, ln2_lo = 1.90821492927058770002e-10;
  const V ln = e * ln2_hi + (2.0 * s * series + e * ln2_lo);
  return ln * 0.43429448190325182765;  // 1 / ln 10
}

template <class V, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION V fabs_(V a) {
  for (int l = 0; l < LaneCount<V>::value; ++l) a[l] = fabs_(a[l]);  // vectorized (a sign mask)
  return a;
}

// Lane by lane as compat.hpp's min_ and max_ on doubles (the same choice at ties and NaN).
template <class V, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION V min_(const V& a, const V& b) {
  return a < b ? a : b;
}
template <class V, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION V max_(const V& a, const V& b) {
  return a > b ? a : b;
}

// Eight consecutive (x, y) pairs of an interleaved array (a LayoutRight [n][2] view at node n):
// x and y each as one vector, from two vector loads and two shuffles (a gather per component
// would cost far more). And the reverse, added in place.
KOKKOS_FORCEINLINE_FUNCTION void load_pairs(const double* pairs, Double8& x, Double8& y) {
  Double8 lo, hi;
  __builtin_memcpy(&lo, pairs, sizeof lo);
  __builtin_memcpy(&hi, pairs + 8, sizeof hi);
  x = __builtin_shuffle(lo, hi, Mask8{0, 2, 4, 6, 8, 10, 12, 14});
  y = __builtin_shuffle(lo, hi, Mask8{1, 3, 5, 7, 9, 11, 13, 15});
}
KOKKOS_FORCEINLINE_FUNCTION void add_pairs(double* pairs, const Double8& x, const Double8& y) {
  Double8 lo, hi;
  __builtin_memcpy(&lo, pairs, sizeof lo);
  __builtin_memcpy(&hi, pairs + 8, sizeof hi);
  lo += __builtin_shuffle(x, y, Mask8{0, 8, 1, 9, 2, 10, 3, 11});
  hi += __builtin_shuffle(x, y, Mask8{4, 12, 5, 13, 6, 14, 7, 15});
  __builtin_memcpy(pairs, &lo, sizeof lo);
  __builtin_memcpy(pairs + 8, &hi, sizeof hi);
}
KOKKOS_FORCEINLINE_FUNCTION void store_pairs(double* pairs, const Double8& x, const Double8& y) {
  const Double8 lo = __builtin_shuffle(x, y, Mask8{0, 8, 1, 9, 2, 10, 3, 11});
  const Double8 hi = __builtin_shuffle(x, y, Mask8{4, 12, 5, 13, 6, 14, 7, 15});
  __builtin_memcpy(pairs, &lo, sizeof lo);
  __builtin_memcpy(pairs + 8, &hi, sizeof hi);
}
// The same for four consecutive pairs.
KOKKOS_FORCEINLINE_FUNCTION void load_pairs(const double* pairs, Double4& x, Double4& y) {
  Double4 lo, hi;
  __builtin_memcpy(&lo, pairs, sizeof lo);
  __builtin_memcpy(&hi, pairs + 4, sizeof hi);
  x = __builtin_shuffle(lo, hi, Mask4{0, 2, 4, 6});
  y = __builtin_shuffle(lo, hi, Mask4{1, 3, 5, 7});
}
KOKKOS_FORCEINLINE_FUNCTION void store_pairs(double* pairs, const Double4& x, const Double4& y) {
  const Double4 lo = __builtin_shuffle(x, y, Mask4{0, 4, 1, 5});
  const Double4 hi = __builtin_shuffle(x, y, Mask4{2, 6, 3, 7});
  __builtin_memcpy(pairs, &lo, sizeof lo);
  __builtin_memcpy(pairs + 4, &hi, sizeof hi);
}
KOKKOS_FORCEINLINE_FUNCTION void add_pairs(double* pairs, const Double4& x, const Double4& y) {
  Double4 lo, hi;
  __builtin_memcpy(&lo, pairs, sizeof lo);
  __builtin_memcpy(&hi, pairs + 4, sizeof hi);
  lo += __builtin_shuffle(x, y, Mask4{0, 4, 1, 5});
  hi += __builtin_shuffle(x, y, Mask4{2, 6, 3, 7});
  __builtin_memcpy(pairs, &lo, sizeof lo);
  __builtin_memcpy(pairs + 4, &hi, sizeof hi);
}
// Eight consecutive (a, b, c) triples of an interleaved array (a LayoutRight [n][3] view at row
// n): a, b and c each as one vector, from three vector loads and six two-source shuffles.
KOKKOS_FORCEINLINE_FUNCTION void load_triples(const double* triples, Double8& a, Double8& b,
                                              Double8& c) {
  Double8 p, q, r;
  __builtin_memcpy(&p, triples, sizeof p);
  __builtin_memcpy(&q, triples + 8, sizeof q);
  __builtin_memcpy(&r, triples + 16, sizeof r);
  // Element 3l + m of the 24 is lane l of component m; first from p:q (indices 0-15), then the
  // last lanes from r (second operand indices 8-15 = r's 0-7).
  a = __builtin_shuffle(__builtin_shuffle(p, q, Mask8{0, 3, 6, 9, 12, 15, 0, 0}), r,
                        Mask8{0, 1, 2, 3, 4, 5, 10, 13});
  b = __builtin_shuffle(__builtin_shuffle(p, q, Mask8{1, 4, 7, 10, 13, 0, 0, 0}), r,
                        Mask8{0, 1, 2, 3, 4, 8, 11, 14});
  c = __builtin_shuffle(__builtin_shuffle(p, q, Mask8{2, 5, 8, 11, 14, 0, 0, 0}), r,
                        Mask8{0, 1, 2, 3, 4, 9, 12, 15});
}

// The reverse of load_triples: a, b and c stored as eight interleaved (a, b, c) triples.
KOKKOS_FORCEINLINE_FUNCTION void store_triples(double* triples, const Double8& a, const Double8& b,
                                               const Double8& c) {
  // Element 3l + m of the 24 is lane l of component m: each 8 of them from a and b, then c.
  const Double8 p = __builtin_shuffle(__builtin_shuffle(a, b, Mask8{0, 8, 0, 1, 9, 0, 2, 10}), c,
                                      Mask8{0, 1, 8, 3, 4, 9, 6, 7});
  const Double8 q = __builtin_shuffle(__builtin_shuffle(a, b, Mask8{0, 3, 11, 0, 4, 12, 0, 5}), c,
                                      Mask8{10, 1, 2, 11, 4, 5, 12, 7});
  const Double8 r = __builtin_shuffle(__builtin_shuffle(a, b, Mask8{13, 0, 6, 14, 0, 7, 15, 0}), c,
                                      Mask8{0, 13, 2, 3, 14, 5, 6, 15});
  __builtin_memcpy(triples, &p, sizeof p);
  __builtin_memcpy(triples + 8, &q, sizeof q);
  __builtin_memcpy(triples + 16, &r, sizeof r);
}

// Four consecutive (a, b, c) triples, as load_triples: element 3l + m of the 12 is lane l of
// component m.
KOKKOS_FORCEINLINE_FUNCTION void load_triples(const double* triples, Double4& a, Double4& b,
                                              Double4& c) {
  Double4 p, q, r;
  __builtin_memcpy(&p, triples, sizeof p);
  __builtin_memcpy(&q, triples + 4, sizeof q);
  __builtin_memcpy(&r, triples + 8, sizeof r);
  a = __builtin_shuffle(__builtin_shuffle(p, q, Mask4{0, 3, 6, 0}), r, Mask4{0, 1, 2, 5});
  b = __builtin_shuffle(__builtin_shuffle(p, q, Mask4{1, 4, 7, 0}), r, Mask4{0, 1, 2, 6});
  c = __builtin_shuffle(__builtin_shuffle(p, q, Mask4{2, 5, 0, 0}), r, Mask4{0, 1, 4, 7});
}
KOKKOS_FORCEINLINE_FUNCTION void store_triples(double* triples, const Double4& a, const Double4& b,
                                               const Double4& c) {
  const Double4 p =
      __builtin_shuffle(__builtin_shuffle(a, b, Mask4{0, 4, 0, 1}), c, Mask4{0, 1, 4, 3});
  const Double4 q =
      __builtin_shuffle(__builtin_shuffle(a, b, Mask4{5, 0, 2, 6}), c, Mask4{0, 5, 2, 3});
  const Double4 r =
      __builtin_shuffle(__builtin_shuffle(a, b, Mask4{0, 3, 7, 0}), c, Mask4{6, 1, 2, 7});
  __builtin_memcpy(triples, &p, sizeof p);
  __builtin_memcpy(triples + 4, &q, sizeof q);
  __builtin_memcpy(triples + 8, &r, sizeof r);
}

// Eight lanes into consecutive doubles at p, write-only: a non-temporal store where p is a whole
// cache line (AVX-512), which does not first read the line it overwrites (a store that misses
// the cache reads it first: twice the traffic for an array the kernel only writes); else a plain
// store. A thread's streamed stores are ordered by stream_fence(), which it must run before its
// results are used (before the end of its work).
KOKKOS_FORCEINLINE_FUNCTION void stream_lanes(const Double8& v, double* p) {
#if defined(__AVX512F__)
  if ((reinterpret_cast<unsigned long>(p) & 63) == 0) {
    _mm512_stream_pd(p, reinterpret_cast<__m512d>(v));
    return;
  }
#endif
  __builtin_memcpy(p, &v, sizeof v);
}
KOKKOS_FORCEINLINE_FUNCTION void stream_fence() {
#if defined(__AVX512F__)
  _mm_sfence();
#endif
}

// Lane l of the result is lane l - 1 of v; lane 0 is 0.
KOKKOS_FORCEINLINE_FUNCTION Double8 shift_up_one_lane(const Double8& v) {
  return __builtin_shuffle(v, Double8{}, Mask8{8, 0, 1, 2, 3, 4, 5, 6});
}
KOKKOS_FORCEINLINE_FUNCTION Double4 shift_up_one_lane(const Double4& v) {
  return __builtin_shuffle(v, Double4{}, Mask4{4, 0, 1, 2});
}

// Sixteen 32-bit ints (e.g. the (i, j) pairs of eight rows of a LayoutRight [n][2] int view) and
// eight, as vectors; the lanes of a comparison are 0 or -1.
typedef int Int16 __attribute__((vector_size(64)));
typedef int Int8 __attribute__((vector_size(32)));
KOKKOS_FORCEINLINE_FUNCTION Int16 load_ints16(const int* p) {
  Int16 v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
KOKKOS_FORCEINLINE_FUNCTION Int8 load_ints8(const int* p) {
  Int8 v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
// True if every lane of the comparison result m is set.
KOKKOS_FORCEINLINE_FUNCTION bool all_set(const Int16& m) {
#if defined(__AVX512F__)
  return _mm512_test_epi32_mask(reinterpret_cast<__m512i>(m), reinterpret_cast<__m512i>(m)) ==
         0xFFFF;
#else
  int r = -1;
  for (int l = 0; l < 16; ++l) r &= m[l];
  return r == -1;
#endif
}
KOKKOS_FORCEINLINE_FUNCTION bool all_set(const Int8& m) {
  int r = -1;
  for (int l = 0; l < 8; ++l) r &= m[l];
  return r == -1;
}
// The even and the odd lanes of v (the first and the second column of eight [n][2] rows).
KOKKOS_FORCEINLINE_FUNCTION Int8 even_lanes(const Int16& v) {
  return __builtin_shufflevector(v, v, 0, 2, 4, 6, 8, 10, 12, 14);
}
KOKKOS_FORCEINLINE_FUNCTION Int8 odd_lanes(const Int16& v) {
  return __builtin_shufflevector(v, v, 1, 3, 5, 7, 9, 11, 13, 15);
}
// A comparison result of eight ints widened to the lanes of a Double8 select.
KOKKOS_FORCEINLINE_FUNCTION Mask8 widen(const Int8& m) {
  return __builtin_convertvector(m, Mask8);
}
// Four ints, as Int8.
typedef int Int4 __attribute__((vector_size(16)));
KOKKOS_FORCEINLINE_FUNCTION Int4 load_ints4(const int* p) {
  Int4 v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
KOKKOS_FORCEINLINE_FUNCTION bool all_set(const Int4& m) {
  return (m[0] & m[1] & m[2] & m[3]) == -1;
}
KOKKOS_FORCEINLINE_FUNCTION Mask4 widen(const Int4& m) {
  return __builtin_convertvector(m, Mask4);
}
// The int lanes that go with L double lanes, and their load.
template <int L>
struct IntLanes;
template <>
struct IntLanes<8> {
  using type = Int8;
  static Int8 load(const int* p) { return load_ints8(p); }
};
template <>
struct IntLanes<4> {
  using type = Int4;
  static Int4 load(const int* p) { return load_ints4(p); }
};

// Rows index[l] of a LayoutRight [n][3] array at base, as three values of one lane per row,
// and back: whole vectors (load_triples) when the rows are consecutive, else row by row.
template <class V, int L, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION void load_triple_lanes(const double* base, const int (&index)[L],
                                                   V (&v)[3]) {
  static_assert(L == LaneCount<V>::value, "one row per lane");
  if (index[L - 1] - index[0] == L - 1) {
    load_triples(base + 3 * index[0], v[0], v[1], v[2]);
    return;
  }
  for (int c = 0; c < 3; ++c) v[c] = gather_lanes<V, L>(base + c, index, 3);
}
template <class V, int L, if_lanes<V> = 0>
KOKKOS_FORCEINLINE_FUNCTION void store_triple_lanes(double* base, const int (&index)[L],
                                                    const V (&v)[3]) {
  static_assert(L == LaneCount<V>::value, "one row per lane");
  if (index[L - 1] - index[0] == L - 1) {
    store_triples(base + 3 * index[0], v[0], v[1], v[2]);
    return;
  }
  for (int l = 0; l < L; ++l)
    for (int c = 0; c < 3; ++c) base[3 * index[l] + c] = v[c][l];
}

// Items per work item of the batched kernels (element, bond and node batches) on this build.
inline constexpr int kLanes = 8;
// The lane type of the element kernel and the kicks: as many lanes as one vector register holds
// doubles. Their state per lane is large (an element's corners, gradients, stresses and its
// material's temporaries), and eight lanes on a machine without AVX-512 take two registers per
// value and spill: measured on an AVX2 machine (AMD EPYC, 2 threads, level 4 of
// bench/penetration), the element kernel took 2.7 (plane scene) to 3.3 (main job) times as long
// with eight lanes as with four, and 2 to 2.7 times as long element by element
// (docs/performance.md).
#if defined(__AVX512F__)
using NativeDouble = Double8;
#else
using NativeDouble = Double4;
#endif
#else
inline constexpr int kLanes = 1;
using NativeDouble = double;
#endif
// Lanes of NativeDouble (a divisor of kLanes).
inline constexpr int kNativeLanes = LaneCount<NativeDouble>::value;

}  // namespace fracta
