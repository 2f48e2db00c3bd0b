// GoogleTest entry point: initialises Kokkos once, except when only listing tests (Kokkos 3.4
// prints its OMP_PROC_BIND warning on stdout, which would corrupt ctest's test discovery).
#include <gtest/gtest.h>
#include <Kokkos_Core.hpp>
#include <cstring>

int main(int argc, char** argv) {
  bool listing = false;
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--gtest_list_tests", 18) == 0) listing = true;
  ::testing::InitGoogleTest(&argc, argv);
  if (listing) return RUN_ALL_TESTS();
  Kokkos::ScopeGuard kokkos(argc, argv);
  return RUN_ALL_TESTS();
}
