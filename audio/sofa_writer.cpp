#include "audio/sofa_writer.h"

#include <netcdf.h>

#include <ctime>
#include <initializer_list>
#include <utility>
#include <vector>

#include "common/input_error.h"

namespace dpc::audio {
namespace {

/// One open netCDF file; every call checked, closed on destruction.
class NcFile {
 public:
  NcFile(std::string path, const std::string& file) : path_(std::move(path)) {
    check(nc_create(file.c_str(), NC_NETCDF4 | NC_CLOBBER, &id_));
  }
  ~NcFile() {
    if (id_ >= 0) nc_close(id_);
  }
  NcFile(const NcFile&) = delete;
  NcFile& operator=(const NcFile&) = delete;
  void check(int status) const {
    if (status != NC_NOERR)
      throw InputError(path_, "", std::string("cannot write SOFA: ") + nc_strerror(status));
  }
  int dim(const char* name, size_t length) {
    int d = -1;
    check(nc_def_dim(id_, name, length, &d));
    return d;
  }
  int var(const char* name, nc_type type, std::initializer_list<int> dims) {
    int v = -1;
    const std::vector<int> ids(dims);
    check(nc_def_var(id_, name, type, int(ids.size()), ids.data(), &v));
    return v;
  }
  void text(int var, const char* name, const std::string& value) {
    check(nc_put_att_text(id_, var, name, value.size(), value.c_str()));
  }
  void endDefinitions() { check(nc_enddef(id_)); }
  void put(int var, const double* data) { check(nc_put_var_double(id_, var, data)); }
  void close() {
    const int id = std::exchange(id_, -1);
    check(nc_close(id));
  }

 private:
  std::string path_;
  int id_ = -1;
};

struct Dims {
  int i, c, r, e, n, m;
};

void globalAttributes(NcFile& f, const SofaIrs& irs) {
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S", std::gmtime(&now));
  const std::pair<const char*, std::string> attrs[] = {
      {"Conventions", "SOFA"},
      {"Version", "2.1"},
      {"SOFAConventions", "GeneralFIR"},
      {"SOFAConventionsVersion", "1.0"},
      {"APIName", "dpc (netCDF-C)"},
      {"APIVersion", "1.0"},
      {"ApplicationName", "dpc"},
      {"ApplicationVersion", "1.0"},
      {"AuthorContact", "n/a"},
      {"Organization", "n/a"},
      {"License", "No license provided, ask the author for permission"},
      {"DataType", "FIR"},
      {"RoomType", irs.roomType},
      {"Title", irs.title},
      {"Comment", irs.comment},
      {"DateCreated", date},
      {"DateModified", date}};
  for (const auto& [name, value] : attrs) f.text(NC_GLOBAL, name, value);
}

/// A position variable: cartesian, metres.
int positionVar(NcFile& f, const char* name, std::initializer_list<int> dims) {
  const int v = f.var(name, NC_DOUBLE, dims);
  f.text(v, "Type", "cartesian");
  f.text(v, "Units", "metre");
  return v;
}

void checkShapes(const std::string& path, const SofaIrs& irs) {
  auto bad = [&](const std::string& why) {
    throw InputError(path, "", "cannot write SOFA: " + why);
  };
  if (irs.sampleRate <= 0) bad("sample rate not positive");
  if (irs.irs.empty() || irs.irs[0].channels() == 0 || irs.irs[0].samples() == 0)
    bad("no IR samples");
  if (irs.sourcePositions.size() != irs.irs.size()) bad("one source position per measurement");
  if (irs.receiverPositions.size() != size_t(irs.irs[0].channels()))
    bad("one position per receiver");
  for (const ImpulseResponse& m : irs.irs) {
    if (m.channels() != irs.irs[0].channels()) bad("every measurement needs the same receivers");
    if (m.samples() != irs.irs[0].samples()) bad("every IR needs the same length");
  }
}

}  // namespace

TempOutputFile stageSofa(const std::string& path, const SofaIrs& irs) {
  checkShapes(path, irs);
  TempOutputFile out(path);
  const size_t M = irs.irs.size(), R = size_t(irs.irs[0].channels()), N = irs.irs[0].samples();
  NcFile f(path, out.tempPath());
  const Dims d{f.dim("I", 1), f.dim("C", 3), f.dim("R", R),
               f.dim("E", 1), f.dim("N", N), f.dim("M", M)};
  globalAttributes(f, irs);
  const int listener = positionVar(f, "ListenerPosition", {d.i, d.c});
  const int receivers = positionVar(f, "ReceiverPosition", {d.r, d.c, d.i});
  const int sources = positionVar(f, "SourcePosition", {d.m, d.c});
  const int emitters = positionVar(f, "EmitterPosition", {d.e, d.c, d.i});
  const int view = positionVar(f, "ListenerView", {d.i, d.c});
  const int up = positionVar(f, "ListenerUp", {d.i, d.c});
  const int data = f.var("Data.IR", NC_DOUBLE, {d.m, d.r, d.n});
  const int rate = f.var("Data.SamplingRate", NC_DOUBLE, {d.i});
  f.text(rate, "Units", "hertz");
  const int delay = f.var("Data.Delay", NC_DOUBLE, {d.i, d.r});
  f.endDefinitions();
  f.put(listener, irs.listenerPosition.data());
  f.put(view, irs.listenerView.data());
  f.put(up, irs.listenerUp.data());
  f.put(receivers, irs.receiverPositions.data()->data());
  f.put(sources, irs.sourcePositions.data()->data());
  const Vec3d origin{};
  f.put(emitters, origin.data());
  std::vector<double> samples;  // AES69 stores doubles; float samples convert exactly
  samples.reserve(M * R * N);
  for (const ImpulseResponse& m : irs.irs)  // channel-major: receiver by receiver
    samples.insert(samples.end(), m.data().begin(), m.data().end());
  f.put(data, samples.data());
  const double fs = irs.sampleRate;
  f.put(rate, &fs);
  f.put(delay, std::vector<double>(R, 0.0).data());
  f.close();
  return out;
}

}  // namespace dpc::audio
