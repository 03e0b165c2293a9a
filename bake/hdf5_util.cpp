#include "bake/hdf5_util.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace dpc::bake::h5 {

Id& Id::operator=(Id&& o) noexcept {
  if (this != &o) {
    close();
    id_ = o.id_;
    o.id_ = H5I_INVALID_HID;
  }
  return *this;
}

bool Id::close() {
  if (id_ < 0) return true;
  herr_t status = 0;
  switch (H5Iget_type(id_)) {
    case H5I_FILE: status = H5Fclose(id_); break;
    case H5I_DATASPACE: status = H5Sclose(id_); break;
    case H5I_ATTR: status = H5Aclose(id_); break;
    case H5I_GENPROP_LST: status = H5Pclose(id_); break;
    case H5I_DATATYPE: status = H5Tclose(id_); break;
    default: status = H5Oclose(id_); break;
  }
  id_ = H5I_INVALID_HID;
  return status >= 0;
}

void silenceHdf5() {
  // Before HDF5 starts (else a harmless failure): after a write the system refused, HDF5's
  // own clean-up at exit can crash on the objects that write left half made.
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

namespace {

herr_t innermost(unsigned, const H5E_error2_t* e, void* out) {
  if (e->desc) *static_cast<std::string*>(out) = e->desc;
  return 0;
}

}  // namespace

std::string lastError() {
  std::string desc;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, innermost, &desc);
  // The file drivers put the system's reason in "error message = '...'".
  const std::string key = "error message = '";
  const size_t at = desc.find(key);
  if (at != std::string::npos) {
    const size_t end = desc.find('\'', at + key.size());
    return desc.substr(at + key.size(), end == std::string::npos ? end : end - at - key.size());
  }
  desc.erase(std::remove(desc.begin(), desc.end(), '\n'), desc.end());
  return desc;
}

Id check(hid_t id, const std::string& what) {
  if (id < 0) {
    const std::string why = lastError();
    throw std::runtime_error(why.empty() ? what : what + ": " + why);
  }
  return Id(id);
}

Id fileAccess() {
  Id fapl = check(H5Pcreate(H5P_FILE_ACCESS), "file access properties");
  H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V18, H5F_LIBVER_V18);
  H5Pset_sieve_buf_size(fapl.get(), 0);
  return fapl;
}

Id fileCreation() {
  Id fcpl = check(H5Pcreate(H5P_FILE_CREATE), "file creation properties");
  H5Pset_obj_track_times(fcpl.get(), 0);
  H5Pset_link_phase_change(fcpl.get(), 32, 24);
  H5Pset_attr_phase_change(fcpl.get(), 64, 48);
  return fcpl;
}

void createGroup(hid_t file, const std::string& name) {
  const Id gcpl = check(H5Pcreate(H5P_GROUP_CREATE), name);
  H5Pset_obj_track_times(gcpl.get(), 0);
  check(H5Gcreate2(file, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT),
        "cannot create " + name);
}

Id openFile(const std::string& path, bool writable, std::string& error) {
  const Id fapl = fileAccess();
  Id file(H5Fopen(path.c_str(), writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, fapl.get()));
  if (!file.valid()) error = lastError();  // before closing fapl clears HDF5's error stack
  return file;
}

/// The file's descriptor (the sec2 driver's).
int descriptor(hid_t file) {
  const Id fapl = check(H5Fget_access_plist(file), "file access properties");
  void* handle = nullptr;
  if (H5Fget_vfd_handle(file, fapl.get(), &handle) < 0 || !handle)
    throw std::runtime_error("no file descriptor: " + lastError());
  return *static_cast<int*>(handle);
}

void reserveFile(hid_t file) {
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error(lastError());
  hsize_t size = 0;
  if (H5Fget_filesize(file, &size) < 0) throw std::runtime_error(lastError());
  if (const int e = ::posix_fallocate(descriptor(file), 0, off_t(size)); e != 0)
    throw std::runtime_error(std::strerror(e));
}

void flushToDevice(hid_t file) {
  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error(lastError());
  if (::fsync(descriptor(file)) != 0) throw std::runtime_error(std::strerror(errno));
}

namespace {

/// Writes a scalar attribute: in place when one of the same type and size exists (the object
/// header keeps its layout), else created anew.
void writeScalar(hid_t obj, const std::string& name, hid_t type, const void* value) {
  if (H5Aexists(obj, name.c_str()) > 0) {
    const Id attr = check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "attribute " + name);
    const Id stored = check(H5Aget_type(attr.get()), "attribute " + name);
    if (H5Tequal(stored.get(), type) > 0) {
      if (H5Awrite(attr.get(), type, value) < 0)
        throw std::runtime_error("attribute " + name + ": " + lastError());
      return;
    }
  }
  if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
  const Id space = check(H5Screate(H5S_SCALAR), "attribute " + name);
  const Id attr = check(H5Acreate2(obj, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                        "attribute " + name);
  if (H5Awrite(attr.get(), type, value) < 0)
    throw std::runtime_error("attribute " + name + ": " + lastError());
}

/// Throws unless attribute `name` exists: "missing", or HDF5's reason it cannot tell (a
/// damaged object header fails its checksum).
void requireAttribute(hid_t obj, const std::string& name) {
  const htri_t exists = H5Aexists(obj, name.c_str());
  if (exists < 0) throw std::runtime_error("attribute " + name + " unreadable: " + lastError());
  if (exists == 0) throw std::runtime_error("attribute " + name + " missing");
}

void readScalar(hid_t obj, const std::string& name, hid_t type, void* value) {
  requireAttribute(obj, name);
  const Id attr = check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "attribute " + name);
  const Id stored = check(H5Aget_type(attr.get()), "attribute " + name);
  const Id space = check(H5Aget_space(attr.get()), "attribute " + name);
  if (H5Tget_class(stored.get()) != H5Tget_class(type) ||
      H5Sget_simple_extent_type(space.get()) != H5S_SCALAR)
    throw std::runtime_error("attribute " + name + " has the wrong type");
  if (H5Aread(attr.get(), type, value) < 0)
    throw std::runtime_error("attribute " + name + " unreadable");
}

/// A fixed-length C string type of n bytes.
Id stringType(size_t n) {
  Id type = check(H5Tcopy(H5T_C_S1), "string type");
  H5Tset_size(type.get(), n);
  H5Tset_strpad(type.get(), H5T_STR_NULLTERM);
  return type;
}

}  // namespace

void writeAttribute(hid_t obj, const std::string& name, int64_t value) {
  writeScalar(obj, name, H5T_NATIVE_INT64, &value);
}
void writeAttribute(hid_t obj, const std::string& name, uint64_t value) {
  writeScalar(obj, name, H5T_NATIVE_UINT64, &value);
}
void writeAttribute(hid_t obj, const std::string& name, double value) {
  writeScalar(obj, name, H5T_NATIVE_DOUBLE, &value);
}
void writeAttribute(hid_t obj, const std::string& name, const std::string& value) {
  const Id type = stringType(value.size() + 1);
  writeScalar(obj, name, type.get(), value.c_str());
}

int64_t readInt(hid_t obj, const std::string& name) {
  int64_t v = 0;
  readScalar(obj, name, H5T_NATIVE_INT64, &v);
  return v;
}
uint64_t readUint(hid_t obj, const std::string& name) {
  uint64_t v = 0;
  readScalar(obj, name, H5T_NATIVE_UINT64, &v);
  return v;
}
double readDouble(hid_t obj, const std::string& name) {
  double v = 0;
  readScalar(obj, name, H5T_NATIVE_DOUBLE, &v);
  return v;
}

std::string readString(hid_t obj, const std::string& name) {
  requireAttribute(obj, name);
  const Id attr = check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "attribute " + name);
  const Id stored = check(H5Aget_type(attr.get()), "attribute " + name);
  if (H5Tget_class(stored.get()) != H5T_STRING || H5Tis_variable_str(stored.get()) > 0)
    throw std::runtime_error("attribute " + name + " is not a fixed-length string");
  const size_t n = H5Tget_size(stored.get());
  if (n == 0 || n > (1u << 16)) throw std::runtime_error("attribute " + name + " has a bad size");
  std::string s(n, '\0');
  const Id type = stringType(n);
  if (H5Aread(attr.get(), type.get(), s.data()) < 0)
    throw std::runtime_error("attribute " + name + " unreadable");
  s.resize(s.find('\0') == std::string::npos ? n : s.find('\0'));
  return s;
}

void createDataset(hid_t file, const std::string& name, hid_t type,
                   const std::vector<hsize_t>& dims) {
  const Id space = check(H5Screate_simple(int(dims.size()), dims.data(), nullptr), name);
  const Id dcpl = check(H5Pcreate(H5P_DATASET_CREATE), name);
  H5Pset_alloc_time(dcpl.get(), H5D_ALLOC_TIME_EARLY);
  H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER);  // reserveFile() makes the zeros
  H5Pset_obj_track_times(dcpl.get(), 0);
  check(H5Dcreate2(file, name.c_str(), type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
        "cannot create " + name);
}

bool exists(hid_t file, const std::string& name) {
  // H5Lexists of "a/b" fails when "a" is absent: check each level.
  for (size_t at = name.find('/'); ; at = name.find('/', at + 1)) {
    const htri_t found = H5Lexists(file, name.substr(0, at).c_str(), H5P_DEFAULT);
    if (found < 0) throw std::runtime_error("unreadable: " + lastError());
    if (found == 0) return false;
    if (at == std::string::npos) return true;
  }
}

std::vector<hsize_t> datasetDims(hid_t file, const std::string& name) {
  if (!exists(file, name)) throw std::runtime_error("missing");
  const Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "missing");
  const Id space = check(H5Dget_space(set.get()), "no dataspace");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0 || rank > 8) throw std::runtime_error("bad dataspace");
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

namespace {

/// Rows [first, first + rows) of an open dataset: its file selection and a memory space.
struct RowSelection {
  Id file, memory;
};

RowSelection selectRows(hid_t set, const std::string& name, size_t first, size_t rows) {
  RowSelection s;
  s.file = check(H5Dget_space(set), name);
  std::vector<hsize_t> dims(size_t(std::max(H5Sget_simple_extent_ndims(s.file.get()), 1)));
  H5Sget_simple_extent_dims(s.file.get(), dims.data(), nullptr);
  if (first + rows > dims[0]) throw std::runtime_error(name + ": rows beyond the dataset");
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  start[0] = first;
  count[0] = rows;
  H5Sselect_hyperslab(s.file.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                      nullptr);
  s.memory = check(H5Screate_simple(int(count.size()), count.data(), nullptr), name);
  return s;
}

}  // namespace

void writeRows(hid_t file, const std::string& name, hid_t type, size_t first, size_t rows,
               const void* data) {
  Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "cannot open " + name);
  const RowSelection s = selectRows(set.get(), name, first, rows);
  if (H5Dwrite(set.get(), type, s.memory.get(), s.file.get(), H5P_DEFAULT, data) < 0)
    throw std::runtime_error(lastError());
  if (!set.close()) throw std::runtime_error(lastError());
}

void readRows(hid_t file, const std::string& name, hid_t type, size_t first, size_t rows,
              void* data) {
  const Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "cannot open " + name);
  const RowSelection s = selectRows(set.get(), name, first, rows);
  if (H5Dread(set.get(), type, s.memory.get(), s.file.get(), H5P_DEFAULT, data) < 0)
    throw std::runtime_error("/" + name + ": unreadable (truncated or corrupt): " + lastError());
}

void writeAll(hid_t file, const std::string& name, hid_t type, const void* data) {
  Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "cannot open " + name);
  if (H5Dwrite(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw std::runtime_error(lastError());
  if (!set.close()) throw std::runtime_error(lastError());
}

void readAll(hid_t file, const std::string& name, hid_t type, void* data) {
  const Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "cannot open " + name);
  if (H5Dread(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw std::runtime_error("/" + name + ": unreadable (truncated or corrupt): " + lastError());
}

}  // namespace dpc::bake::h5
