// Kokkos 3.4 / 4.x compatibility and the project's basic types.
// Kokkos 3.4 keeps math in Kokkos::Experimental and has no Kokkos::min/max; 4.x moved them
// to Kokkos::. Everything in src/kernels uses these wrappers so both versions (and CUDA)
// compile unchanged.
#pragma once
#include <Kokkos_Core.hpp>
#include <string>

// The device code path: atomic node scatter (kernels/scatter.hpp), one lane per work item (no
// host SIMD, kernels/simd.hpp) and LayoutLeft views. GPU builds always take it; a CPU build takes
// it when configured with -DFRACTA_DEVICE_PATH=ON, so that the suite runs the GPU's code on the
// CPU (docs/development.md, "The device path").
#if defined(KOKKOS_ENABLE_CUDA) || defined(KOKKOS_ENABLE_HIP) || defined(KOKKOS_ENABLE_SYCL) || \
    defined(FRACTA_EMULATE_DEVICE)
#define FRACTA_DEVICE_PATH 1
#endif

// A function the host compiler keeps out of line, so that a rarely taken branch does not change
// the code (and the contraction of products into multiply-adds) of the hot loop that calls it.
#if defined(__GNUC__) && !defined(__CUDA_ARCH__)
#define FRACTA_NOINLINE __attribute__((noinline))
#else
#define FRACTA_NOINLINE
#endif

namespace fracta {

using ExecSpace = Kokkos::DefaultExecutionSpace;
using MemSpace = ExecSpace::memory_space;
using HostSpace = Kokkos::HostSpace;

// The execution space's own layout (LayoutRight on CPUs, LayoutLeft on GPUs), LayoutLeft on the
// device path: code must not assume either (host copies go through deep_copy, never data()).
#ifdef FRACTA_DEVICE_PATH
template <class T>
using View = Kokkos::View<T, Kokkos::LayoutLeft, MemSpace>;
#else
template <class T>
using View = Kokkos::View<T, MemSpace>;
#endif
// Per-item vectors stored by component (LayoutLeft): component k of consecutive items is
// contiguous, so the SIMD element kernel (fe_forces.hpp, simd.hpp) moves one component of
// eight elements with one vector load or store.
template <class T>
using ColumnView = Kokkos::View<T, Kokkos::LayoutLeft, MemSpace>;

KOKKOS_INLINE_FUNCTION double sqrt_(double a) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::sqrt(a);
#else
  return Kokkos::Experimental::sqrt(a);
#endif
}
// sqrt(a^2 + b^2) without overflow, as std::hypot on the host (whose value the set-up's
// reference lengths had).
KOKKOS_INLINE_FUNCTION double hypot_(double a, double b) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::hypot(a, b);
#else
  return Kokkos::Experimental::hypot(a, b);
#endif
}
KOKKOS_INLINE_FUNCTION double fabs_(double a) {
  return a < 0.0 ? -a : a;
}
KOKKOS_INLINE_FUNCTION double min_(double a, double b) {
  return a < b ? a : b;
}
KOKKOS_INLINE_FUNCTION double max_(double a, double b) {
  return a > b ? a : b;
}
KOKKOS_INLINE_FUNCTION int min_(int a, int b) {
  return a < b ? a : b;
}
KOKKOS_INLINE_FUNCTION int max_(int a, int b) {
  return a > b ? a : b;
}
KOKKOS_INLINE_FUNCTION double atan2_(double y, double x) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::atan2(y, x);
#else
  return Kokkos::Experimental::atan2(y, x);
#endif
}
KOKKOS_INLINE_FUNCTION double cos_(double a) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::cos(a);
#else
  return Kokkos::Experimental::cos(a);
#endif
}
KOKKOS_INLINE_FUNCTION double sin_(double a) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::sin(a);
#else
  return Kokkos::Experimental::sin(a);
#endif
}
KOKKOS_INLINE_FUNCTION double log_(double a) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::log(a);
#else
  return Kokkos::Experimental::log(a);
#endif
}
KOKKOS_INLINE_FUNCTION double log10_(double a) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::log10(a);
#else
  return Kokkos::Experimental::log10(a);
#endif
}
KOKKOS_INLINE_FUNCTION double exp_(double a) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::exp(a);
#else
  return Kokkos::Experimental::exp(a);
#endif
}
// a b + c, fused (one rounding) wherever the machine has the instruction, else two roundings:
// the same in the SIMD lanes' fma_ (simd.hpp), so that code written with it rounds alike in one
// lane and in the scalar path, which a compiler's own contraction of a b + c does not promise.
KOKKOS_INLINE_FUNCTION double fma_(double a, double b, double c) {
#if defined(__CUDA_ARCH__)
  return ::fma(a, b, c);
#elif defined(__FMA__)
  return __builtin_fma(a, b, c);
#else
  return a * b + c;
#endif
}
KOKKOS_INLINE_FUNCTION double pow_(double a, double b) {
#if KOKKOS_VERSION >= 40000
  return Kokkos::pow(a, b);
#else
  return Kokkos::Experimental::pow(a, b);
#endif
}
KOKKOS_INLINE_FUNCTION bool isfinite_(double a) {
  return a - a == 0.0;
}

// A named profiling region for Kokkos Tools (Kokkos 3.4 has no Profiling::ScopedRegion). Host.
class ProfilingRegion {
 public:
  explicit ProfilingRegion(const std::string& name) { Kokkos::Profiling::pushRegion(name); }
  ~ProfilingRegion() { Kokkos::Profiling::popRegion(); }
  ProfilingRegion(const ProfilingRegion&) = delete;
  ProfilingRegion& operator=(const ProfilingRegion&) = delete;
};

}  // namespace fracta
