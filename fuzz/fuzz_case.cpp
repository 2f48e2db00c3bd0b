// libFuzzer harness for the case parser and the mesh generator (scripts/fuzz.sh builds and runs
// it). Every input must either give a Case and a mesh, or an InputError whose message starts
// with the file name ("fuzz.toml:LINE: KEY: message"); anything else (another exception, a
// crash, a sanitizer report, a hang or an allocation past libFuzzer's -rss_limit_mb) is a bug.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "host/case.hpp"
#include "host/memory.hpp"
#include "host/mesh.hpp"

namespace {
const char* const kSourceName = "fuzz.toml";

// What build_model checks on the host before it touches the device: every selector of a load or
// boundary is evaluated on the mesh (the device part needs Kokkos, which this harness omits).
void select_everything(const fracta::Case& c, const fracta::HostMesh& mesh) {
  for (const fracta::Load& l : c.loads) {
    if (l.where.kind == fracta::NodeSelector::Kind::segment)
      (void)fracta::select_edges(mesh, l.where.segment, l.body_index);
    (void)fracta::select_nodes(mesh, l.where, l.body_index);
  }
  for (const fracta::Boundary& b : c.boundaries)
    (void)fracta::select_nodes(mesh, b.where, b.body_index);
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // 64 MB: a few hundred thousand cells at most, so a mutant that asks for a fine mesh is
  // refused by check_memory (as it would be on a small machine) instead of timing out here.
  setenv("FRACTA_MEMORY_LIMIT_BYTES", "64e6", 1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const unsigned char* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const fracta::Case c = fracta::parse_case(text, kSourceName);
    const fracta::HostMesh mesh = fracta::build_mesh(c);
    select_everything(c, mesh);
  } catch (const fracta::InputError& e) {
    const std::string what = e.what();
    if (what.rfind(std::string(kSourceName) + ":", 0) != 0 ||
        what.size() <= std::string(kSourceName).size() + 2) {
      std::fprintf(stderr, "InputError without 'FILE:LINE: KEY: message': '%s'\n", what.c_str());
      std::abort();
    }
  }
  // Any other exception escapes: libFuzzer reports it as a crash.
  return 0;
}
