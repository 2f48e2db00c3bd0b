// Memory estimate of a case before its mesh is built, and the check that refuses a case that
// would not fit (docs/output.md: bad input, exit code 2). Host-only, no Kokkos: the fuzz harness
// links it without the device code.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "host/case.hpp"

namespace fracta {

// The grid a body's mesh is fitted to: cells of about cell_size over the shape's bounding box.
// Doubles, so that absurd inputs (1e308 m wide, 1e-300 m cells) are counted without overflow.
struct BodyGrid {
  double nx = 0, ny = 0;  // cells along x and y (0 when the shape is smaller than one cell)
  double cells() const { return nx * ny; }
  double nodes() const { return (nx + 1) * (ny + 1); }
};
BodyGrid body_grid(const Body& b);

struct MemoryEstimate {
  // Peak resident memory of a run (B), see memory.cpp for what it counts: with the cells of the
  // adaptive bodies as FE (the memory a cell's lattice state takes grows as it converts:
  // sparse_zero_view.hpp), and if every one of them converts.
  double bytes = 0;
  double bytes_all_converted = 0;
  double cells = 0;       // upper bound: every cell of every body's bounding-box grid
  double nodes = 0;       // upper bound, likewise
  int largest_body = -1;  // the body with the largest share of `bytes` (-1: no body)
};
MemoryEstimate estimate_memory(const Case& c);

// Bytes available for a run: FRACTA_MEMORY_LIMIT_BYTES when set (tests, batch systems), else
// MemAvailable from /proc/meminfo; a negative value when neither is known (no check then).
// Throws InputError for a malformed FRACTA_MEMORY_LIMIT_BYTES.
double available_memory_bytes();

// Throws InputError at the largest body's cell_size when the case would need more cells than
// the mesh's 32-bit indices can address, or more memory than available_memory_bytes() at its
// start (MemoryEstimate::bytes).
void check_memory(const Case& c);

// Fixes glibc's mmap threshold at 1 MiB, so every host block of 1 MiB or more (a large mesh's
// views) gets a mapping of its own. Left dynamic, glibc raises the threshold to the size of any
// mapped block that is freed: once the set-up frees a large host vector, views up to that size
// come from the heap instead, and the element kernel of a million-cell mesh ran 1.5 times
// slower (1.16e6 elements, one thread: 21 against 14 ms per sweep; the same with huge pages).
// build_model calls it before it allocates, so every program that builds a model has it (fracta,
// the benchmarks, the tests); a no-op off glibc.
void keep_large_blocks_mapped();

// Sets bytes at data to zero, lazily where it can: on Linux the whole pages are handed back to
// the kernel (madvise MADV_DONTNEED), so each reads as zero and costs memory only once it is
// written; the partial pages at the ends are cleared at once. For state that the run writes in
// a small part only (the bond slots of cells that never convert): see sparse_zero_view in
// model.hpp. Elsewhere, and if the kernel refuses, a plain memset.
void zero_lazily(void* data, size_t bytes);

// "1.5 GB", "320 MB": for messages.
std::string format_bytes(double bytes);

}  // namespace fracta
