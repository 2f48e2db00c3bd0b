// Wall time per named profiling region ("fracta::fe_forces", ...), taken in-process through
// Kokkos' tools callbacks (Kokkos::Tools::Experimental::set_push_region_callback, present in
// Kokkos 3.4 and 4.x), so no tool library has to be loaded.
//
// A region nested in itself counts once, for its outermost occurrence: "fracta::contact_search"
// is pushed by Simulation::evaluate_forces around ContactSystem::update and again by
// ContactSystem::rebuild; "fracta::contact_forces" likewise. `calls` counts outermost entries.
// The callbacks fence, so on an asynchronous backend (CUDA) a region's time includes its
// kernels; on OpenMP the fence is a no-op.
#pragma once
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include <Kokkos_Core.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "kernels/state.hpp"  // fracta::kSlotLabel

namespace fracta::bench {

struct RegionTotals {
  double seconds = 0.0;  // s, outermost occurrences only
  long calls = 0;
};

class RegionTimer {
 public:
  // Call after Kokkos is initialised.
  static void install() {
    Kokkos::Tools::Experimental::set_push_region_callback(&push);
    Kokkos::Tools::Experimental::set_pop_region_callback(&pop);
  }
  // Detaches the callbacks (regions cost nothing again).
  static void uninstall() {
    Kokkos::Tools::Experimental::set_push_region_callback(nullptr);
    Kokkos::Tools::Experimental::set_pop_region_callback(nullptr);
    reset();
  }
  static void reset() {
    state().totals.clear();
    state().stack.clear();
  }
  static const std::map<std::string, RegionTotals>& totals() { return state().totals; }
  static RegionTotals get(const std::string& name) {
    const auto it = state().totals.find(name);
    return it == state().totals.end() ? RegionTotals{} : it->second;
  }

 private:
  using Clock = std::chrono::steady_clock;
  struct State {
    std::vector<std::pair<std::string, Clock::time_point>> stack;
    std::map<std::string, RegionTotals> totals;
  };
  static State& state() {
    static State s;
    return s;
  }
  static void push(const char* name) {
    Kokkos::fence();
    state().stack.emplace_back(name, Clock::now());
  }
  static void pop() {
    Kokkos::fence();
    State& s = state();
    if (s.stack.empty()) return;  // popped a region pushed before install()/reset()
    const auto [name, start] = s.stack.back();
    s.stack.pop_back();
    for (const auto& outer : s.stack)
      if (outer.first == name) return;  // nested in itself: the outer occurrence counts
    RegionTotals& t = s.totals[name];
    t.seconds += std::chrono::duration<double>(Clock::now() - start).count();
    ++t.calls;
  }
};

// What the host asks of the device, counted through the same callbacks. On a GPU each
// parallel_reduce into a host value and each deep_copy between host and device makes the host
// wait for the device (a round trip); parallel_for and scan launches, and reductions into a slot
// in device memory (fracta::ResultSlot, labelled with fracta::kSlotLabel), queue without waiting.
struct LaunchCounts {
  long fors = 0, reduces = 0, scans = 0, deep_copies = 0;
  long slot_reduces = 0;  // of the reduces, those into a slot
  long launches() const { return fors + reduces + scans; }
  long host_reduces() const { return reduces - slot_reduces; }
  LaunchCounts operator-(const LaunchCounts& o) const {
    return {fors - o.fors, reduces - o.reduces, scans - o.scans, deep_copies - o.deep_copies,
            slot_reduces - o.slot_reduces};
  }
  LaunchCounts& operator+=(const LaunchCounts& o) {
    fors += o.fors, reduces += o.reduces, scans += o.scans, deep_copies += o.deep_copies;
    slot_reduces += o.slot_reduces;
    return *this;
  }
};

// Wall time per kernel name (parallel_for / reduce / scan), through the same tools callbacks:
// where a phase's time goes, kernel by kernel. A kernel's time runs from its launch to its end
// (on OpenMP the launch is synchronous). `calls` counts launches; counts() the launches by kind
// and the deep copies.
class KernelTimer {
 public:
  static void install() {
    namespace T = Kokkos::Tools::Experimental;
    T::set_begin_parallel_for_callback(&begin_for);
    T::set_end_parallel_for_callback(&end);
    T::set_begin_parallel_reduce_callback(&begin_reduce);
    T::set_end_parallel_reduce_callback(&end);
    T::set_begin_parallel_scan_callback(&begin_scan);
    T::set_end_parallel_scan_callback(&end);
    T::set_begin_deep_copy_callback(&deep_copy);
  }
  static void uninstall() {
    namespace T = Kokkos::Tools::Experimental;
    T::set_begin_parallel_for_callback(nullptr);
    T::set_end_parallel_for_callback(nullptr);
    T::set_begin_parallel_reduce_callback(nullptr);
    T::set_end_parallel_reduce_callback(nullptr);
    T::set_begin_parallel_scan_callback(nullptr);
    T::set_end_parallel_scan_callback(nullptr);
    T::set_begin_deep_copy_callback(nullptr);
    reset();
    state().open.clear();
  }
  static void reset() { state().totals.clear(); }
  static const std::map<std::string, RegionTotals>& totals() { return state().totals; }
  static LaunchCounts counts() { return state().counts; }

 private:
  using Clock = std::chrono::steady_clock;
  struct State {
    std::vector<std::pair<std::string, Clock::time_point>> open;  // indexed by kernel id
    std::map<std::string, RegionTotals> totals;
    LaunchCounts counts;  // since install()
  };
  static State& state() {
    static State s;
    return s;
  }
  static void begin(const char* name, uint64_t* id) {
    State& s = state();
    *id = s.open.size();
    s.open.emplace_back(name, Clock::now());
  }
  static void begin_for(const char* name, const uint32_t, uint64_t* id) {
    ++state().counts.fors;
    begin(name, id);
  }
  static void begin_reduce(const char* name, const uint32_t, uint64_t* id) {
    ++state().counts.reduces;
    const size_t n = std::strlen(name), k = std::strlen(fracta::kSlotLabel);
    if (n >= k && std::strcmp(name + n - k, fracta::kSlotLabel) == 0) ++state().counts.slot_reduces;
    begin(name, id);
  }
  static void begin_scan(const char* name, const uint32_t, uint64_t* id) {
    ++state().counts.scans;
    begin(name, id);
  }
  static void deep_copy(Kokkos::Tools::SpaceHandle, const char*, const void*,
                        Kokkos::Tools::SpaceHandle, const char*, const void*, uint64_t) {
    ++state().counts.deep_copies;
  }
  static void end(const uint64_t id) {
    State& s = state();
    if (id >= s.open.size()) return;
    RegionTotals& t = s.totals[s.open[id].first];
    t.seconds += std::chrono::duration<double>(Clock::now() - s.open[id].second).count();
    ++t.calls;
    if (id + 1 == s.open.size()) s.open.pop_back();  // kernels do not overlap on the host
  }
};

// Memory held in Kokkos views, by label, through the tools' allocation callbacks: what the
// state of a run costs, entity by entity. allocated(): the bytes of each label's views now;
// resident(): the part of them in RAM (mincore(2), host memory on Linux; else the allocation),
// which is less where a view's pages were never touched (sparse_zero_view, model.hpp). peak():
// the largest total allocated at any time since install().
class ViewMemory {
 public:
  static void install() {
    namespace T = Kokkos::Tools::Experimental;
    T::set_allocate_data_callback(&allocate);
    T::set_deallocate_data_callback(&deallocate);
  }
  static std::map<std::string, double> allocated() {
    std::map<std::string, double> bytes;
    for (const auto& [ptr, block] : state().blocks) bytes[block.label] += block.size;
    return bytes;
  }
  static std::map<std::string, double> resident() {
    std::map<std::string, double> bytes;
    for (const auto& [ptr, block] : state().blocks)
      bytes[block.label] += block.host ? resident_bytes(ptr, block.size) : block.size;
    return bytes;
  }
  static double peak() { return state().peak; }

 private:
  struct Block {
    std::string label;
    double size = 0;
    bool host = false;
  };
  struct State {
    std::map<const void*, Block> blocks;
    double total = 0, peak = 0;
  };
  static State& state() {
    static State s;
    return s;
  }
  static double resident_bytes(const void* ptr, const double size) {
#if defined(__linux__)
    const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
    const uintptr_t begin = reinterpret_cast<uintptr_t>(ptr) / page * page;
    const uintptr_t end = reinterpret_cast<uintptr_t>(ptr) + static_cast<uintptr_t>(size);
    std::vector<unsigned char> in_core((end - begin + page - 1) / page);
    if (mincore(reinterpret_cast<void*>(begin), end - begin, in_core.data()) != 0) return size;
    double pages = 0;
    for (const unsigned char c : in_core) pages += c & 1;
    return std::min(size, pages * static_cast<double>(page));
#else
    (void)ptr;
    return size;
#endif
  }
  static void allocate(const Kokkos::Tools::SpaceHandle space, const char* label, const void* ptr,
                       const uint64_t size) {
    State& s = state();
    s.blocks[ptr] = {label, static_cast<double>(size), std::string(space.name) == "Host"};
    s.total += static_cast<double>(size);
    s.peak = std::max(s.peak, s.total);
  }
  static void deallocate(Kokkos::Tools::SpaceHandle, const char*, const void* ptr,
                         const uint64_t size) {
    State& s = state();
    s.blocks.erase(ptr);
    s.total -= static_cast<double>(size);
  }
};

}  // namespace fracta::bench
