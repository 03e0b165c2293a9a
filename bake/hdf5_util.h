// Small RAII and typed helpers over the HDF5 C API for the bake file (bake/bake_file.h):
// an owned identifier, scalar attributes, and float datasets whose first dimension is the
// probe. Errors: HDF5's own error printing is switched off (silenceHdf5); a failed call throws
// std::runtime_error naming the object, which the bake file turns into a line naming its file.
// Control thread; allocates.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

namespace dpc::bake::h5 {

/// An owned HDF5 identifier, closed with H5Oclose/H5Fclose/H5Sclose/H5Aclose/H5Pclose by kind.
class Id {
 public:
  Id() = default;
  explicit Id(hid_t id) : id_(id) {}
  Id(Id&& o) noexcept : id_(o.id_) { o.id_ = H5I_INVALID_HID; }
  Id& operator=(Id&& o) noexcept;
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  ~Id() { close(); }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void close();

 private:
  hid_t id_ = H5I_INVALID_HID;
};

/// Switches off HDF5's automatic error printing (errors become exceptions here). Idempotent.
void silenceHdf5();

/// Throws std::runtime_error("what") when id < 0; returns the owned id.
Id check(hid_t id, const std::string& what);

void writeAttribute(hid_t obj, const std::string& name, int64_t value);
void writeAttribute(hid_t obj, const std::string& name, uint64_t value);
void writeAttribute(hid_t obj, const std::string& name, double value);
void writeAttribute(hid_t obj, const std::string& name, const std::string& value);
/// Reads a scalar attribute; throws std::runtime_error naming it when absent or not numeric.
int64_t readInt(hid_t obj, const std::string& name);
uint64_t readUint(hid_t obj, const std::string& name);
double readDouble(hid_t obj, const std::string& name);
std::string readString(hid_t obj, const std::string& name);

/// Creates a dataset of `dims` (first: the probe count, chunked one probe per chunk when
/// chunked is set) of native type `type`.
void createDataset(hid_t file, const std::string& name, hid_t type,
                   const std::vector<hsize_t>& dims, bool chunked);
/// The dataset's dimensions; throws std::runtime_error when it does not exist.
std::vector<hsize_t> datasetDims(hid_t file, const std::string& name);
/// Writes / reads row `row` (first index) of a dataset of `type`; `data` holds the row.
void writeRow(hid_t file, const std::string& name, hid_t type, size_t row, const void* data);
/// Writes / reads a whole dataset of `type`.
void writeAll(hid_t file, const std::string& name, hid_t type, const void* data);
void readAll(hid_t file, const std::string& name, hid_t type, void* data);

}  // namespace dpc::bake::h5
