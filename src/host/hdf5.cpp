#include "host/hdf5.hpp"

#include <fcntl.h>
#include <hdf5.h>  // host only: the CUDA check skips the files that include it
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace fracta::h5 {

namespace {

herr_t innermost_error(unsigned n, const H5E_error2_t* e, void* data) {
  if (n == 0 && e->desc) *static_cast<std::string*>(data) = e->desc;
  return 0;
}

// A variable-length UTF-8 string type.
Handle string_type(const Io& io, const std::string& what) {
  Handle type(io.id(H5Tcopy(H5T_C_S1), what), H5Tclose);
  io.ok(H5Tset_size(type.get(), H5T_VARIABLE), what);
  io.ok(H5Tset_cset(type.get(), H5T_CSET_UTF8), what);
  return type;
}

std::string shape(const std::vector<hsize_t>& dims) {
  std::ostringstream s;
  s << "(";
  for (size_t k = 0; k < dims.size(); ++k) s << (k ? ", " : "") << dims[k];
  s << ")";
  return s.str();
}

}  // namespace

void silence_error_stack() {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

void Io::fail(const std::string& what) const {
  std::string detail;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost_error, &detail);
  H5Eclear2(H5E_DEFAULT);
  // The file drivers' messages run over several lines with addresses and offsets; the system's
  // own reason ("No space left on device") is what a user can act on.
  const std::string quoted = "error message = '";
  const std::size_t reason = detail.find(quoted);
  if (reason != std::string::npos) {
    const std::size_t begin = reason + quoted.size(), end = detail.find('\'', begin);
    detail = detail.substr(0, detail.find(':')) + ": " + detail.substr(begin, end - begin);
  }
  detail = detail.substr(0, detail.find('\n'));
  throw IoError((context_.empty() ? "" : context_ + ": ") + what +
                (detail.empty() ? "" : " (HDF5: " + detail + ")"));
}

std::string Io::where(hid_t loc, const std::string& name) {
  char buf[512] = "";
  H5Iget_name(loc, buf, sizeof buf);
  const std::string base = buf;
  if (name.empty()) return base;
  return (base == "/" ? "" : base) + "/" + name;
}

namespace {
Handle file_access(const Io& io, bool portable, bool in_memory) {
  Handle fapl(io.id(H5Pcreate(H5P_FILE_ACCESS), "cannot create file access properties"), H5Pclose);
  // The core driver without a backing store: the file lives in memory, grown by 1 MiB.
  if (in_memory)
    io.ok(H5Pset_fapl_core(fapl.get(), 1 << 20, false), "cannot select the in-memory driver");
  if (portable)
    io.ok(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_EARLIEST, H5F_LIBVER_V18),
          "cannot set library version bounds");
  return fapl;
}
}  // namespace

Handle Io::create_file(const std::string& path, bool portable) const {
  const Handle fapl = file_access(*this, portable, false);
  return Handle(id(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()),
                   "cannot create file " + path),
                H5Fclose);
}

Handle Io::create_memory_file(bool portable) const {
  const Handle fapl = file_access(*this, portable, true);
  // The name only labels the image: nothing is written under it.
  return Handle(id(H5Fcreate("fracta-memory-image.h5", H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()),
                   "cannot create a file in memory"),
                H5Fclose);
}

void Io::write_image(Handle& file, const std::string& path) const {
  const std::string what = "cannot make the image of " + path;
  ok(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), what);
  const ssize_t size = H5Fget_file_image(file.get(), nullptr, 0);
  if (size < 0) fail(what);
  std::vector<char> image(static_cast<size_t>(size));
  if (H5Fget_file_image(file.get(), image.data(), image.size()) != size) fail(what);
  ok(file.close(), what);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) fail("cannot create " + path + ": " + std::strerror(errno));
  size_t done = 0;
  while (done < image.size()) {
    const ssize_t n = ::write(fd, image.data() + done, image.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? std::strerror(errno) : "nothing written";
      ::close(fd);
      remove_file(path);
      fail("cannot write " + path + ": " + why);
    }
    done += static_cast<size_t>(n);
  }
  if (::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    remove_file(path);
    fail("cannot write " + path + ": " + why);
  }
}

void Io::remove_file(const std::string& path) {
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

void Io::close_file(Handle& file, const std::string& path) const {
  ok(file.close(), "cannot write " + path + " whole (file system full?)");
}

void Io::require_space(const std::string& path, std::uintmax_t bytes,
                       const std::string& what) const {
  std::error_code ec;
  std::filesystem::path dir(path);
  if (!std::filesystem::is_directory(dir, ec)) dir = dir.parent_path();
  if (dir.empty()) dir = ".";
  const std::filesystem::space_info info = std::filesystem::space(dir, ec);
  if (ec) fail("cannot read the free space of " + dir.string() + ": " + ec.message());
  if (info.available < bytes)
    fail("not enough space on the file system of " + dir.string() + " to write " + what +
         ": it needs about " + std::to_string(bytes) + " bytes, " + std::to_string(info.available) +
         " are available");
  // A file-size limit (ulimit -f) fails a write just as a full file system does.
  struct rlimit limit;
  if (getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
      limit.rlim_cur < bytes)
    fail("the file-size limit (ulimit -f) of " + std::to_string(limit.rlim_cur) +
         " bytes is below the about " + std::to_string(bytes) + " bytes of " + what);
}

Handle Io::open_read(const std::string& path) const {
  return Handle(id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "cannot open " + path),
                H5Fclose);
}

Handle Io::create_group(hid_t loc, const std::string& name) const {
  return Handle(id(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                   "cannot create group " + where(loc, name)),
                H5Gclose);
}

Handle Io::open_group(hid_t loc, const std::string& name) const {
  if (!exists(loc, name)) fail("group " + where(loc, name) + " is missing");
  return Handle(
      id(H5Gopen2(loc, name.c_str(), H5P_DEFAULT), "cannot open group " + where(loc, name)),
      H5Gclose);
}

bool Io::exists(hid_t loc, const std::string& name) const {
  return H5Lexists(loc, name.c_str(), H5P_DEFAULT) > 0;
}

template <class T>
void Io::write_attribute(hid_t obj, const char* name, const T& value) const {
  const auto what = [&] { return "cannot write attribute " + where(obj, "") + " " + name; };
  if (H5Aexists(obj, name) > 0) ok(H5Adelete(obj, name), what);
  Handle space(id(H5Screate(H5S_SCALAR), what), H5Sclose);
  if constexpr (std::is_same_v<T, std::string>) {
    const Handle type = string_type(*this, what());
    Handle attr(id(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), what),
                H5Aclose);
    const char* p = value.c_str();
    ok(H5Awrite(attr.get(), type.get(), &p), what);
  } else {
    Handle attr(
        id(H5Acreate2(obj, name, Types<T>::file(), space.get(), H5P_DEFAULT, H5P_DEFAULT), what),
        H5Aclose);
    ok(H5Awrite(attr.get(), Types<T>::mem(), &value), what);
  }
}

template <class T>
T Io::read_attribute(hid_t obj, const char* name) const {
  const auto what = [&] { return "cannot read attribute " + where(obj, "") + " " + name; };
  if (H5Aexists(obj, name) <= 0) fail("attribute " + where(obj, "") + " " + name + " is missing");
  Handle attr(id(H5Aopen(obj, name, H5P_DEFAULT), what), H5Aclose);
  if constexpr (std::is_same_v<T, std::string>) {
    const Handle type = string_type(*this, what());
    char* p = nullptr;
    ok(H5Aread(attr.get(), type.get(), &p), what);
    std::string s = p ? p : "";
    H5free_memory(p);
    return s;
  } else {
    T value{};
    ok(H5Aread(attr.get(), Types<T>::mem(), &value), what);
    return value;
  }
}

template <class T>
void Io::write_array(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims,
                     const std::vector<T>& values, const Storage& storage) const {
  const auto what = [&] { return "cannot write dataset " + where(loc, name); };
  Handle space(id(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), what),
               H5Sclose);
  const hid_t file_type =
      std::is_floating_point_v<T> && storage.single_precision ? H5T_IEEE_F32LE : Types<T>::file();
  Handle dcpl(id(H5Pcreate(H5P_DATASET_CREATE), what), H5Pclose);
  if (storage.deflate > 0 && !values.empty() && !dims.empty()) {
    // Chunks of whole rows, at most 2^18 values: small enough for HDF5's 1 MiB chunk cache.
    std::vector<hsize_t> chunk = dims;
    hsize_t row = 1;
    for (std::size_t d = 1; d < dims.size(); ++d) row *= dims[d];
    chunk[0] = std::max<hsize_t>(1, std::min<hsize_t>(dims[0], (hsize_t{1} << 18) / row));
    ok(H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data()), what);
    ok(H5Pset_shuffle(dcpl.get()), what);
    ok(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(storage.deflate)), what);
  }
  Handle ds(id(H5Dcreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT, dcpl.get(),
                          H5P_DEFAULT),
               what),
            H5Dclose);
  if (values.empty()) return;
  if (file_type == H5T_IEEE_F32LE) {
    // Rounded here, not by HDF5: its conversion path goes through a zeroed 1 MiB buffer per
    // write, which made a float32 frame slower to write than a float64 one. The buffer is kept
    // (a fresh one per array costs its page faults, as much as the write at 10^6 nodes).
    thread_local std::vector<float> rounded;
    rounded.assign(values.begin(), values.end());
    ok(H5Dwrite(ds.get(), H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, rounded.data()), what);
  } else {
    ok(H5Dwrite(ds.get(), Types<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), what);
  }
}

template <class T>
void Io::write_scalar(hid_t loc, const std::string& name, T value) const {
  const auto what = [&] { return "cannot write dataset " + where(loc, name); };
  Handle space(id(H5Screate(H5S_SCALAR), what), H5Sclose);
  Handle ds(id(H5Dcreate2(loc, name.c_str(), Types<T>::file(), space.get(), H5P_DEFAULT,
                          H5P_DEFAULT, H5P_DEFAULT),
               what),
            H5Dclose);
  ok(H5Dwrite(ds.get(), Types<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &value), what);
}

template <class T>
std::vector<T> Io::read_array(hid_t loc, const std::string& name,
                              const std::vector<hsize_t>& dims) const {
  const auto what = [&] { return "cannot read dataset " + where(loc, name); };
  if (!exists(loc, name)) fail("dataset " + name + " is missing");
  Handle ds(id(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), what), H5Dclose);
  Handle space(id(H5Dget_space(ds.get()), what), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> got(rank > 0 ? rank : 0);
  if (rank < 0 || H5Sget_simple_extent_dims(space.get(), got.data(), nullptr) < 0) fail(what());
  if (got != dims)
    fail("dataset " + name + " has shape " + shape(got) + ", the model needs " + shape(dims));
  size_t n = 1;
  for (hsize_t d : dims) n *= d;
  std::vector<T> values(n);
  if (n > 0)
    ok(H5Dread(ds.get(), Types<T>::mem(), H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), what);
  return values;
}

hsize_t Io::size_of(hid_t loc, const std::string& name) const {
  const auto what = [&] { return "cannot read dataset " + where(loc, name); };
  if (!exists(loc, name)) fail("dataset " + name + " is missing");
  Handle ds(id(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), what), H5Dclose);
  Handle space(id(H5Dget_space(ds.get()), what), H5Sclose);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0) fail(what());
  return static_cast<hsize_t>(n);
}

template <class T>
void Io::create_series(hid_t loc, const char* name, hsize_t chunk_rows) const {
  const auto what = [&] { return "cannot create dataset " + where(loc, name); };
  const hsize_t zero = 0, unlimited = H5S_UNLIMITED;
  Handle space(id(H5Screate_simple(1, &zero, &unlimited), what), H5Sclose);
  Handle dcpl(id(H5Pcreate(H5P_DATASET_CREATE), what), H5Pclose);
  ok(H5Pset_chunk(dcpl.get(), 1, &chunk_rows), what);
  Handle ds(
      id(H5Dcreate2(loc, name, Types<T>::file(), space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
         what),
      H5Dclose);
}

template <class T>
void Io::append_series(hid_t loc, const char* name, const std::vector<T>& values) const {
  if (values.empty()) return;
  const auto what = [&] { return "cannot append to " + where(loc, name); };
  Handle ds(id(H5Dopen2(loc, name, H5P_DEFAULT), what), H5Dclose);
  hsize_t old_rows = 0;
  {
    Handle space(id(H5Dget_space(ds.get()), what), H5Sclose);
    ok(H5Sget_simple_extent_dims(space.get(), &old_rows, nullptr), what);
  }
  const hsize_t count = values.size(), rows = old_rows + count;
  ok(H5Dset_extent(ds.get(), &rows), what);
  Handle file_space(id(H5Dget_space(ds.get()), what), H5Sclose);
  ok(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &old_rows, nullptr, &count, nullptr),
     what);
  Handle mem_space(id(H5Screate_simple(1, &count, nullptr), what), H5Sclose);
  ok(H5Dwrite(ds.get(), Types<T>::mem(), mem_space.get(), file_space.get(), H5P_DEFAULT,
              values.data()),
     what);
}

#define FRACTA_H5_NUMERIC(T)                                                               \
  template void Io::write_attribute<T>(hid_t, const char*, const T&) const;                \
  template T Io::read_attribute<T>(hid_t, const char*) const;                              \
  template void Io::write_array<T>(hid_t, const std::string&, const std::vector<hsize_t>&, \
                                   const std::vector<T>&, const Storage&) const;           \
  template void Io::write_scalar<T>(hid_t, const std::string&, T) const;                   \
  template std::vector<T> Io::read_array<T>(hid_t, const std::string&,                     \
                                            const std::vector<hsize_t>&) const;            \
  template void Io::create_series<T>(hid_t, const char*, hsize_t) const;                   \
  template void Io::append_series<T>(hid_t, const char*, const std::vector<T>&) const;
FRACTA_H5_NUMERIC(double)
FRACTA_H5_NUMERIC(std::int64_t)
FRACTA_H5_NUMERIC(int)
#undef FRACTA_H5_NUMERIC
template void Io::write_attribute<std::string>(hid_t, const char*, const std::string&) const;
template std::string Io::read_attribute<std::string>(hid_t, const char*) const;

}  // namespace fracta::h5
