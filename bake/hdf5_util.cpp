#include "bake/hdf5_util.h"

#include <algorithm>
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

void Id::close() {
  if (id_ < 0) return;
  switch (H5Iget_type(id_)) {
    case H5I_FILE: H5Fclose(id_); break;
    case H5I_DATASPACE: H5Sclose(id_); break;
    case H5I_ATTR: H5Aclose(id_); break;
    case H5I_GENPROP_LST: H5Pclose(id_); break;
    case H5I_DATATYPE: H5Tclose(id_); break;
    default: H5Oclose(id_); break;
  }
  id_ = H5I_INVALID_HID;
}

void silenceHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

Id check(hid_t id, const std::string& what) {
  if (id < 0) throw std::runtime_error(what);
  return Id(id);
}

namespace {

void writeScalar(hid_t obj, const std::string& name, hid_t type, const void* value) {
  if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
  const Id space = check(H5Screate(H5S_SCALAR), "attribute " + name);
  const Id attr = check(H5Acreate2(obj, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                        "attribute " + name);
  if (H5Awrite(attr.get(), type, value) < 0) throw std::runtime_error("attribute " + name);
}

void readScalar(hid_t obj, const std::string& name, hid_t type, void* value) {
  if (H5Aexists(obj, name.c_str()) <= 0) throw std::runtime_error("attribute " + name + " missing");
  const Id attr = check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "attribute " + name);
  const Id stored = check(H5Aget_type(attr.get()), "attribute " + name);
  if (H5Tget_class(stored.get()) != H5Tget_class(type))
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
  if (H5Aexists(obj, name.c_str()) <= 0) throw std::runtime_error("attribute " + name + " missing");
  const Id attr = check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "attribute " + name);
  const Id stored = check(H5Aget_type(attr.get()), "attribute " + name);
  if (H5Tget_class(stored.get()) != H5T_STRING || H5Tis_variable_str(stored.get()) > 0)
    throw std::runtime_error("attribute " + name + " is not a fixed-length string");
  const size_t n = H5Tget_size(stored.get());
  std::string s(n, '\0');
  const Id type = stringType(n);
  if (H5Aread(attr.get(), type.get(), s.data()) < 0)
    throw std::runtime_error("attribute " + name + " unreadable");
  s.resize(s.find('\0') == std::string::npos ? n : s.find('\0'));
  return s;
}

void createDataset(hid_t file, const std::string& name, hid_t type,
                   const std::vector<hsize_t>& dims, bool chunked) {
  const Id space = check(H5Screate_simple(int(dims.size()), dims.data(), nullptr), name);
  const Id lcpl = check(H5Pcreate(H5P_LINK_CREATE), name);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  const Id dcpl = check(H5Pcreate(H5P_DATASET_CREATE), name);
  if (chunked) {
    std::vector<hsize_t> chunk = dims;
    chunk[0] = 1;
    H5Pset_chunk(dcpl.get(), int(chunk.size()), chunk.data());
  }
  check(H5Dcreate2(file, name.c_str(), type, space.get(), lcpl.get(), dcpl.get(), H5P_DEFAULT),
        "cannot create " + name);
}

std::vector<hsize_t> datasetDims(hid_t file, const std::string& name) {
  const Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "missing");
  const Id space = check(H5Dget_space(set.get()), "no dataspace");
  std::vector<hsize_t> dims(size_t(std::max(H5Sget_simple_extent_ndims(space.get()), 0)));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

void writeRow(hid_t file, const std::string& name, hid_t type, size_t row, const void* data) {
  const Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "cannot open " + name);
  const Id space = check(H5Dget_space(set.get()), name);
  std::vector<hsize_t> dims(size_t(H5Sget_simple_extent_ndims(space.get())));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  start[0] = row;
  count[0] = 1;
  H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  const Id memory = check(H5Screate_simple(int(count.size()), count.data(), nullptr), name);
  if (H5Dwrite(set.get(), type, memory.get(), space.get(), H5P_DEFAULT, data) < 0)
    throw std::runtime_error("cannot write " + name);
}

void writeAll(hid_t file, const std::string& name, hid_t type, const void* data) {
  const Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "cannot open " + name);
  if (H5Dwrite(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw std::runtime_error("cannot write " + name);
}

void readAll(hid_t file, const std::string& name, hid_t type, void* data) {
  const Id set = check(H5Dopen2(file, name.c_str(), H5P_DEFAULT), "cannot open " + name);
  if (H5Dread(set.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw std::runtime_error("unreadable (truncated or corrupt)");
}

}  // namespace dpc::bake::h5
