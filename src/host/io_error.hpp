// The error of a file that could not be written or read: a full file system, a missing or
// unwritable directory, a failed write, sync or rename. A run that meets one ends with exit
// code 4 and writes nothing more, so every file written before stays complete.
#pragma once
#include <stdexcept>

namespace fracta {

struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace fracta
