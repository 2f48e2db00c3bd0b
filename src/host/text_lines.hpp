// Splitting text into lines and joining them back (the checkpoint's --set overrides, the case
// mutator of the fuzz test). Host-only.
#pragma once
#include <sstream>
#include <string>
#include <vector>

namespace fracta {

// Lines of `text` without their '\n' (a final line without one is kept).
inline std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

// Each line followed by '\n'.
inline std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

}  // namespace fracta
