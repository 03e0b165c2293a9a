// Small RAII and typed helpers over the HDF5 C API for the bake file (bake/bake_file.h):
// an owned identifier, the file's fixed layout (format bounds, no timestamps, every dataset
// allocated and filled when it is created), scalar attributes, and float datasets whose first
// dimension is the probe. Errors: HDF5's own error printing is switched off (silenceHdf5); a
// failed call throws std::runtime_error naming the object and, for a failed read or write,
// the system's reason (lastError), which the bake file turns into a line naming its file.
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
  /// Closes the identifier; false when HDF5 reports an error (a file whose last writes fail).
  bool close();

 private:
  hid_t id_ = H5I_INVALID_HID;
};

/// Switches off HDF5's automatic error printing (errors become exceptions here). Idempotent.
void silenceHdf5();

/// The innermost reason on HDF5's error stack of this thread: the system's message of a failed
/// read or write ("No space left on device"), else HDF5's own description; "" when empty.
std::string lastError();

/// Throws std::runtime_error("what: " + lastError()) when id < 0; returns the owned id.
Id check(hid_t id, const std::string& what);

/// File access: the object formats of HDF5 1.8 (superblock 2 and object headers 2, each
/// checksummed), whatever library writes the file, so that one build's files are the same
/// bytes everywhere; 1.10's superblock 3 is avoided because a writer killed with the file open
/// leaves it unreadable to every tool until h5clear. No sieve buffer: a dataset write reaches
/// the file within H5Dwrite, whose status then says whether the system took it (buffered, a
/// refused write surfaced only when the dataset was closed, and HDF5 crashed at exit).
Id fileAccess();
/// File creation: no timestamps, and up to 32 links kept in the root group's own (checksummed)
/// object header.
Id fileCreation();
/// Creates `name` (and no intermediate group) as a group without timestamps.
void createGroup(hid_t file, const std::string& name);

/// Opens the file with fileAccess(); an invalid Id on failure, with lastError() in `error`.
Id openFile(const std::string& path, bool writable, std::string& error);
/// Flushes the file and reserves its whole size on the device (posix_fallocate): a disk too
/// small refuses it here, in dpc's own call, not inside HDF5 (whose state a refused write can
/// leave broken). Throws std::runtime_error with the system's reason.
void reserveFile(hid_t file);
/// H5Fflush, then fsync of the file's descriptor: the data are on the device (or the device
/// refused them). Throws std::runtime_error with the reason on failure.
void flushToDevice(hid_t file);

void writeAttribute(hid_t obj, const std::string& name, int64_t value);
void writeAttribute(hid_t obj, const std::string& name, uint64_t value);
void writeAttribute(hid_t obj, const std::string& name, double value);
void writeAttribute(hid_t obj, const std::string& name, const std::string& value);
/// Reads a scalar attribute; throws std::runtime_error naming it when absent or not numeric.
int64_t readInt(hid_t obj, const std::string& name);
uint64_t readUint(hid_t obj, const std::string& name);
double readDouble(hid_t obj, const std::string& name);
std::string readString(hid_t obj, const std::string& name);

/// Creates a contiguous dataset of `dims` of type `type`, its whole storage allocated in the
/// file now (zeros once reserveFile() has run), so that later writes only overwrite bytes
/// already in the file (a full disk shows itself at creation, not half-way through a bake).
void createDataset(hid_t file, const std::string& name, hid_t type,
                   const std::vector<hsize_t>& dims);
/// Whether `name` (a path of groups, e.g. "wave/band") exists; throws std::runtime_error when
/// the file cannot be read.
bool exists(hid_t file, const std::string& name);
/// The dataset's dimensions; throws std::runtime_error when it does not exist.
std::vector<hsize_t> datasetDims(hid_t file, const std::string& name);
/// Writes / reads `rows` rows from row `first` (first index) of a dataset of `type`; `data`
/// holds the rows.
void writeRows(hid_t file, const std::string& name, hid_t type, size_t first, size_t rows,
               const void* data);
void readRows(hid_t file, const std::string& name, hid_t type, size_t first, size_t rows,
              void* data);
/// Writes / reads a whole dataset of `type`.
void writeAll(hid_t file, const std::string& name, hid_t type, const void* data);
void readAll(hid_t file, const std::string& name, hid_t type, void* data);

}  // namespace dpc::bake::h5
