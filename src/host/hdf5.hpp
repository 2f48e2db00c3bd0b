// The one HDF5 layer of fracta: owned identifiers, the type map, attributes, fixed arrays and
// growing series. The output file (output.cpp) and the checkpoint (checkpoint.cpp) both write
// and read through it, so they share one set of conventions:
// - every identifier is owned by a Handle and closed by it (also when an exception unwinds);
// - a failure throws IoError "CONTEXT: what (HDF5: innermost message)", where the context names
//   the file ("output OUT.h5", "checkpoint"); HDF5's own stderr dump is off;
// - a file is written whole to a temporary name, its close checked (the close is where HDF5
//   writes its last metadata), and only then renamed into place by the caller; the space it
//   needs is checked before HDF5 is asked to write it, because HDF5 1.10 can crash (not fail)
//   when the file system fills up inside an object copy;
// - strings are scalar variable-length UTF-8 attributes (they live in the global heap, so the
//   64 KiB object-header limit does not apply to a long case text); numbers are little-endian
//   IEEE doubles and 32/64-bit integers in the file, native in memory;
// - arrays are written row-major with their shape, and a reader states the shape it needs.
// Host code only: nvcc never sees this header.
#pragma once
#include <hdf5.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "host/io_error.hpp"

namespace fracta::h5 {

// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), close_(o.close_) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
      close_ = o.close_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = H5I_INVALID_HID;
  }
  // Closes now and returns HDF5's status (a file's close is where it writes its last metadata).
  herr_t close() {
    const herr_t status = id_ >= 0 && close_ ? close_(id_) : 0;
    id_ = H5I_INVALID_HID;
    return status;
  }
  hid_t get() const { return id_; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

// The numeric types fracta stores: their memory and file types, and their XDMF description.
template <class T>
struct Types;
template <>
struct Types<double> {
  static hid_t mem() { return H5T_NATIVE_DOUBLE; }
  static hid_t file() { return H5T_IEEE_F64LE; }
  static constexpr const char* xdmf = R"(NumberType="Float" Precision="8")";
};
template <>
struct Types<std::int64_t> {
  static hid_t mem() { return H5T_NATIVE_INT64; }
  static hid_t file() { return H5T_STD_I64LE; }
  static constexpr const char* xdmf = R"(NumberType="Int" Precision="8")";
};
template <>
struct Types<int> {
  static hid_t mem() { return H5T_NATIVE_INT; }
  static hid_t file() { return H5T_STD_I32LE; }
  static constexpr const char* xdmf = R"(NumberType="Int" Precision="4")";
};

// How a fixed array is stored. Floating-point values as float32 (`single_precision`, converted by
// HDF5 on the write) or float64; integers are never narrowed. `deflate` 1-9: chunked (at most
// 2^18 values per chunk, 1 MiB of float32), with the byte shuffle before deflate at that level,
// which HDF5 and h5py undo on read; 0: contiguous, unfiltered.
struct Storage {
  bool single_precision = false;
  int deflate = 0;
};

// Turns HDF5's automatic error printing off for the process: errors become exceptions.
void silence_error_stack();

// The operations, with the context their error messages start with. Numeric templates are
// instantiated for double, std::int64_t and int; attributes also for std::string.
class Io {
 public:
  explicit Io(std::string context) : context_(std::move(context)) {}
  const std::string& context() const { return context_; }

  [[noreturn]] void fail(const std::string& what) const;
  hid_t id(hid_t h, const std::string& what) const {
    if (h < 0) fail(what);
    return h;
  }
  void ok(herr_t status, const std::string& what) const {
    if (status < 0) fail(what);
  }
  // The same with the message made only on failure (`what` returns it): a dataset's absolute
  // name costs a search of HDF5's name tables, too much to make for every array of a frame.
  template <class What, class = std::enable_if_t<std::is_invocable_r_v<std::string, What>>>
  hid_t id(hid_t h, const What& what) const {
    if (h < 0) fail(what());
    return h;
  }
  template <class What, class = std::enable_if_t<std::is_invocable_r_v<std::string, What>>>
  void ok(herr_t status, const What& what) const {
    if (status < 0) fail(what());
  }
  // The absolute name of loc/name, for messages.
  static std::string where(hid_t loc, const std::string& name);

  // A new file (truncated). `portable`: superblock and objects readable by any HDF5 1.8+.
  Handle create_file(const std::string& path, bool portable) const;
  // Closes a file written through create_file; IoError if HDF5 could not write it whole.
  void close_file(Handle& file, const std::string& path) const;
  // Writes the file `path` whole: fill(root) makes its contents. `in_memory`: built in memory
  // and written by one plain write, so a full file system or a file-size limit fails that write
  // and nothing else (HDF5 1.10 can crash, not fail, when a write fails inside an object copy);
  // for files that copy objects and are small. Otherwise HDF5 writes it as it goes, into the
  // room require_space checked. On failure the partial file is removed.
  template <class Fill>
  void write_file(const std::string& path, bool portable, bool in_memory, Fill&& fill) const {
    if (in_memory) {
      Handle file = create_memory_file(portable);
      fill(file.get());
      write_image(file, path);
      return;
    }
    try {
      Handle file = create_file(path, portable);
      fill(file.get());
      close_file(file, path);
    } catch (...) {
      remove_file(path);
      throw;
    }
  }
  // An HDF5 file in memory only, and its image written to `path` (the handle closed).
  Handle create_memory_file(bool portable) const;
  void write_image(Handle& file, const std::string& path) const;
  static void remove_file(const std::string& path);
  // IoError unless the file system of `path` (a file or directory) has `bytes` available and the
  // process may write a file of that size (ulimit -f).
  void require_space(const std::string& path, std::uintmax_t bytes, const std::string& what) const;
  Handle open_read(const std::string& path) const;
  Handle create_group(hid_t loc, const std::string& name) const;
  Handle open_group(hid_t loc, const std::string& name) const;
  bool exists(hid_t loc, const std::string& name) const;

  // Scalar attribute `name` on `obj`, replaced if present.
  template <class T>
  void write_attribute(hid_t obj, const char* name, const T& value) const;
  template <class T>
  T read_attribute(hid_t obj, const char* name) const;

  // A fixed array of shape `dims` (row-major values; zero extents allowed) or a scalar dataset.
  template <class T>
  void write_array(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims,
                   const std::vector<T>& values, const Storage& storage = {}) const;
  template <class T>
  void write_scalar(hid_t loc, const std::string& name, T value) const;
  // Reads array `name`, which must have the shape `dims` (else the message names both shapes).
  template <class T>
  std::vector<T> read_array(hid_t loc, const std::string& name,
                            const std::vector<hsize_t>& dims) const;
  // The element count of dataset `name`.
  hsize_t size_of(hid_t loc, const std::string& name) const;

  // A 1-D series that grows by appends (chunked, unlimited), created empty.
  template <class T>
  void create_series(hid_t loc, const char* name, hsize_t chunk_rows) const;
  template <class T>
  void append_series(hid_t loc, const char* name, const std::vector<T>& values) const;

 private:
  std::string context_;
};

}  // namespace fracta::h5
