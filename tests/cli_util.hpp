// Running the fracta executable from tests (FRACTA_EXE, FRACTA_SOURCE_DIR are compile
// definitions of the test binary).
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace fracta_test {

struct Result {
  int code = -1;
  std::string out;  // stdout + stderr
};

// Runs `fracta ARGS` through the shell; `env` (e.g. "OMP_NUM_THREADS=1") prefixes the command.
inline Result run(const std::string& args, const std::string& env = "") {
  const std::string cmd =
      env + (env.empty() ? "" : " ") + std::string(FRACTA_EXE) + " " + args + " 2>&1";
  Result r;
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::string data(const std::string& rel) {
  return std::string(FRACTA_SOURCE_DIR) + "/tests/data/" + rel;
}

}  // namespace fracta_test
