// Hostile input: deterministic mutants of every case file in cases/ and tests/data/ go through
// the parser, the mesh generator and the model builder. Each stage must either succeed or throw
// InputError with a "FILE:LINE: KEY: message" text; any other exception or a crash fails, and
// absurd meshes are refused by the memory check before anything is allocated (so nothing hangs).
// The libFuzzer harness (fuzz/fuzz_case.cpp, scripts/fuzz.sh) explores further; the inputs it
// found bugs with are the Reproducers below.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "host/case.hpp"
#include "host/memory.hpp"
#include "host/mesh.hpp"
#include "host/model.hpp"
#include "host/text_lines.hpp"
#include "test_util.hpp"

namespace fracta {
namespace {

namespace fs = std::filesystem;
using test::MemoryLimit;

// SplitMix64: the same stream on every platform and standard library (std::*_distribution is
// not), so a failing mutant number reproduces anywhere.
struct Rng {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  size_t below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(next() % n); }
};

struct Seed {
  std::string name;  // path relative to the source tree
  std::string text;
};

std::vector<Seed> seed_cases() {
  std::vector<Seed> seeds;
  const fs::path root(FRACTA_SOURCE_DIR);
  for (const char* dir : {"cases", "tests/data"})
    for (const auto& e : fs::recursive_directory_iterator(root / dir))
      if (e.path().extension() == ".toml") {
        std::ifstream in(e.path(), std::ios::binary);
        std::ostringstream text;
        text << in.rdbuf();
        seeds.push_back({fs::relative(e.path(), root).string(), text.str()});
      }
  std::sort(seeds.begin(), seeds.end(), [](auto& a, auto& b) { return a.name < b.name; });
  return seeds;
}

// Values that break assumptions: zero, negative, overflow, not-a-number, huge and tiny numbers,
// integers beyond 64 bits, empty and nested containers, wrong types, unterminated strings.
const std::vector<std::string> kHostileValues = {
    "0",
    "-1",
    "1e308",
    "-1e308",
    "1e-308",
    "4.9e-324",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "-9223372036854775808",
    "99999999999999999999999",
    "2147483648",
    "1e-7",
    "1e-9",
    "1e-12",
    "\"\"",
    "[]",
    "{}",
    "[[]]",
    "[1, \"a\"]",
    "true",
    "\"plate\"",
    "\"unterminated",
    "[0.0, 1e308]",
    "[nan, inf]",
    "{ type = \"circle\" }",
    "{ type = \"polygon\", points = [[0, 0], [1, 0], [1, 0]] }",
    "{ type = \"rectangle\", x = 0, y = 0, width = 1e308, height = 1e308 }",
    "{ type = \"rectangle\", x = -1e308, y = 0, width = 1e308, height = 1 }",
    "{ type = \"semicircle\", x = 0, y = 0, radius = 1e-300 }",
    "1979-05-27T07:32:00Z"};

std::string deep_nesting(Rng& rng) {
  const size_t depth = 1 + rng.below(3000);
  const bool table = rng.below(2);
  std::string s;
  for (size_t i = 0; i < depth; ++i) s += table ? "{ a = " : "[";
  s += "1";
  for (size_t i = 0; i < depth; ++i) s += table ? " }" : "]";
  return s;
}

// One mutation of the text; the kinds a human or a broken generator would produce.
std::string mutate_once(const std::string& text, Rng& rng) {
  std::vector<std::string> lines = split_lines(text);
  if (lines.empty()) lines.push_back("");
  const size_t k = rng.below(lines.size());
  switch (rng.below(11)) {
    case 0: {  // byte flip
      std::string s = text.empty() ? std::string(1, '\0') : text;
      s[rng.below(s.size())] ^= static_cast<char>(1u << rng.below(8));
      return s;
    }
    case 1: {  // delete a range of bytes
      const size_t at = rng.below(text.size() + 1);
      return text.substr(0, at) + text.substr(std::min(text.size(), at + 1 + rng.below(40)));
    }
    case 2:  // duplicate a line (duplicate keys, tables, array-of-table headers)
      lines.insert(lines.begin() + k, lines[k]);
      return join_lines(lines);
    case 3:  // delete a line (missing keys, orphaned keys)
      lines.erase(lines.begin() + k);
      return join_lines(lines);
    case 4:  // swap two lines (keys move to another table)
      std::swap(lines[k], lines[rng.below(lines.size())]);
      return join_lines(lines);
    case 5:
    case 6: {  // replace a value with a hostile one
      const size_t eq = lines[k].find('=');
      const std::string value =
          rng.below(8) == 0 ? deep_nesting(rng) : kHostileValues[rng.below(kHostileValues.size())];
      if (eq == std::string::npos) return join_lines(lines) + "x = " + value + "\n";
      lines[k] = lines[k].substr(0, eq + 1) + " " + value;
      return join_lines(lines);
    }
    case 7: {  // replace a number inside a line (array elements, inline tables)
      std::string& l = lines[k];
      size_t at = l.find_first_of("0123456789");
      if (at == std::string::npos) return join_lines(lines);
      size_t end = l.find_first_of(" ,]}", at);
      if (end == std::string::npos) end = l.size();
      l = l.substr(0, at) + kHostileValues[rng.below(12)] + l.substr(end);
      return join_lines(lines);
    }
    case 8:  // truncate
      return text.substr(0, rng.below(text.size() + 1));
    case 9: {  // move a line into another section (swap keys between tables)
      const std::string moved = lines[k];
      lines.erase(lines.begin() + k);
      lines.insert(lines.begin() + rng.below(lines.size() + 1), moved);
      return join_lines(lines);
    }
    default: {  // insert random bytes
      std::string junk;
      for (size_t i = 0, n = 1 + rng.below(12); i < n; ++i)
        junk += static_cast<char>(rng.below(256));
      const size_t at = rng.below(text.size() + 1);
      return text.substr(0, at) + junk + text.substr(at);
    }
  }
}

struct Outcome {
  bool parsed = false, meshed = false, modelled = false;
  std::string error;    // InputError text, empty when every stage succeeded
  std::string failure;  // anything that is not allowed (other exception, malformed message)
};

// A "FILE:LINE: KEY: message" text: the file name, then a line number > 0 (the TOML syntax
// errors and model checks all know a line), then at least one more ": " separated part.
std::string malformed_error(const InputError& e, const std::string& file) {
  const std::string what = e.what();
  const std::string prefix = file + ":";
  if (what.rfind(prefix, 0) != 0) return "does not start with '" + prefix + "'";
  if (e.line <= 0) return "has no line number";
  if (what.find(": ", prefix.size()) == std::string::npos) return "has no message";
  return "";
}

Outcome try_case(const std::string& text, const std::string& file, bool build_device_model) {
  Outcome o;
  try {
    const Case c = parse_case(text, file);
    o.parsed = true;
    const HostMesh mesh = build_mesh(c);
    o.meshed = true;
    if (build_device_model) {
      (void)build_model(c);
      o.modelled = true;
    }
  } catch (const InputError& e) {
    o.error = e.what();
    const std::string bad = malformed_error(e, file);
    if (!bad.empty()) o.failure = "InputError " + bad + ": " + o.error;
  } catch (const std::exception& e) {
    o.failure = std::string("unexpected exception: ") + e.what();
  } catch (...) {
    o.failure = "unexpected non-standard exception";
  }
  return o;
}

struct Rejected {
  std::string name, text, error;
};

// The mutants of the corpus test, their outcomes, and a sample of rejected ones for the CLI.
struct Campaign {
  int mutants = 0, parsed = 0, meshed = 0, modelled = 0;
  int valid_seed_mutants = 0, valid_seed_meshed = 0;  // mutants of seeds that mesh unmutated
  std::vector<std::string> failures;
  std::map<std::string, Rejected> rejected_by_key;  // one rejected mutant per error key
};

Campaign run_campaign(int mutants_per_seed) {
  Campaign r;
  // 64 MB: the memory check then refuses meshes beyond some 10^5 cells, as it would on a small
  // machine, so a mutant asking for 10^9 cells costs nothing (and the test cannot hang on one).
  MemoryLimit limit("64e6");
  Rng rng{20261122};
  for (const Seed& seed : seed_cases()) {
    const bool valid_seed = try_case(seed.text, seed.name, false).meshed;
    for (int i = 0; i < mutants_per_seed; ++i) {
      std::string text = seed.text;
      for (size_t n = 1 + rng.below(3); n > 0; --n) text = mutate_once(text, rng);
      const std::string name = seed.name + "~" + std::to_string(i);
      // The device model for one mutant in four: it adds the model checks (selectors that
      // select nothing, lattice range) at a few ms each.
      const Outcome o = try_case(text, name, i % 4 == 0);
      ++r.mutants;
      r.parsed += o.parsed;
      r.meshed += o.meshed;
      r.modelled += o.modelled;
      r.valid_seed_mutants += valid_seed;
      r.valid_seed_meshed += valid_seed && o.meshed;
      if (!o.failure.empty())
        r.failures.push_back(name + ": " + o.failure + "\n--- mutant ---\n" + text);
      if (!o.error.empty()) {
        // The key part of "FILE:LINE: KEY: message" (or the message start for syntax errors).
        const size_t after_line = o.error.find(": ", name.size() + 1);
        const std::string key =
            o.error.substr(after_line + 2, o.error.find(':', after_line + 2) - after_line - 2);
        r.rejected_by_key.emplace(key, Rejected{name, text, o.error});
      }
    }
  }
  return r;
}

TEST(Fuzz, MutantsOfEveryCaseParseOrFailWithInputError) {
  // 34 seed files x 150 mutants: about 5000 mutants, about a second.
  const Campaign r = run_campaign(150);
  EXPECT_GE(r.mutants, 3000);
  for (size_t i = 0; i < r.failures.size() && i < 5; ++i) ADD_FAILURE() << r.failures[i];
  EXPECT_EQ(r.failures.size(), 0u);
  // The mutations must leave enough valid cases for the mesh and model stages to be exercised
  // (a mutant takes 1-3 mutations; one in a comment or of an equal value keeps a case valid):
  // at least 10% of the mutants of valid seeds reach the mesher, and some the device model.
  EXPECT_GE(r.valid_seed_meshed, r.valid_seed_mutants / 10) << r.valid_seed_mutants;
  EXPECT_GE(r.modelled, 20);
  // ...and enough different rejections that the error paths are exercised broadly.
  EXPECT_GE(r.rejected_by_key.size(), 100u);
  std::printf(
      "[ fuzz ] %d mutants: %d parsed, %d meshed (%d of %d from valid seeds), %d device "
      "models, %zu distinct errors\n",
      r.mutants, r.parsed, r.meshed, r.valid_seed_meshed, r.valid_seed_mutants, r.modelled,
      r.rejected_by_key.size());
}

// Inputs the libFuzzer harness found bugs with (tests/data/fuzz/, one file each, named after what
// it found) and their minimal forms. toml_unreachable_non_ascii: a non-ASCII character after a
// value made toml++ 3.3.0 reach __builtin_unreachable() (undefined behaviour, reported by UBSan);
// now refused before toml++ sees it, at its line.
TEST(Fuzz, Reproducers) {
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(FRACTA_SOURCE_DIR) / "tests/data/fuzz")) {
    std::ifstream in(e.path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const Outcome o = try_case(text.str(), e.path().filename().string(), true);
    EXPECT_EQ(o.failure, "") << e.path();
    EXPECT_NE(o.error, "") << e.path();
    ++files;
  }
  EXPECT_GE(files, 1);
  std::string plate;  // cases/penetration.toml: a valid case
  for (const Seed& seed : seed_cases())
    if (seed.name == "cases/penetration.toml") plate = seed.text;
  ASSERT_FALSE(plate.empty());
  ASSERT_TRUE(try_case(plate, "plate.toml", false).meshed);
  for (const char* bad : {"x = 1\xc3\xa9\n", "x = 1 \xc2\xa0\n", "\xe3\x80\x81 = 1\n",
                          "x = [1,\xd0\x80 2]\n", "[a\xc3\xa9]\n"}) {
    const Outcome o = try_case(plate + bad, "reproducer.toml", false);
    EXPECT_EQ(o.failure, "") << bad;
    EXPECT_EQ(o.error.rfind("reproducer.toml:", 0), 0u) << bad << ": " << o.error;
  }
  // Non-ASCII text where TOML allows it (comments, basic and literal strings, with escaped
  // quotes and quote characters inside) still parses.
  std::string ok_text =
      "# Plaque d'acier \xc3\xa9prouv\xc3\xa9"
      "e \"\n" +
      plate;
  const size_t title = ok_text.find("title = ");
  ASSERT_NE(title, std::string::npos);
  ok_text.replace(title, ok_text.find('\n', title) - title,
                  "title = \"\xc3\xa9 \\\" # ' \xe6\x97\xa5\" # d\xc3\xa9j\xc3\xa0 \"vu\"");
  const size_t file = ok_text.find("file = ", ok_text.find("[output]"));
  ASSERT_NE(file, std::string::npos);
  ok_text.replace(file, ok_text.find('\n', file) - file, "file = '\xc3\xa9t\xc3\xa9 \"#.h5'");
  ok_text += "# \xc3\xa9 ' \"\"\" '''\n";
  const Outcome ok = try_case(ok_text, "unicode.toml", false);
  EXPECT_TRUE(ok.meshed) << ok.error << ok.failure;
}

// The CLI on a sample of rejected mutants (one per distinct error key, at most 12): exit code 2,
// and the message on stderr names the file and a line.
TEST(Fuzz, RejectedMutantsExitWithCode2ViaTheCli) {
  const Campaign r = run_campaign(8);
  ASSERT_GE(r.rejected_by_key.size(), 12u);
  const fs::path dir = fs::temp_directory_path() / "fracta_fuzz_cli";
  fs::create_directories(dir);
  size_t step = r.rejected_by_key.size() / 12, k = 0, checked = 0;
  for (const auto& [key, rejected] : r.rejected_by_key) {
    if (k++ % step != 0 || checked == 12) continue;
    const fs::path file = dir / ("mutant_" + std::to_string(checked++) + ".toml");
    std::ofstream(file, std::ios::binary) << rejected.text;
    const std::string cmd = "FRACTA_MEMORY_LIMIT_BYTES=64e6 " + std::string(FRACTA_EXE) +
                            " check " + file.string() + " 2>&1 >/dev/null";
    FILE* p = popen(cmd.c_str(), "r");
    std::string err;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) err.append(buf.data(), n);
    const int status = pclose(p);
    ASSERT_TRUE(WIFEXITED(status)) << rejected.text;
    EXPECT_EQ(WEXITSTATUS(status), 2) << key << ": " << rejected.error << "\n" << err;
    EXPECT_NE(err.find("error: " + file.string() + ":"), std::string::npos) << err;
  }
  EXPECT_EQ(checked, 12u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fracta
