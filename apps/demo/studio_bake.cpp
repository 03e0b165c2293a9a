#include "apps/demo/studio_bake.h"

#include "common/input_error.h"
#ifdef DPC_HAVE_BAKE
#include "bake/bake_file.h"
#include "bake/probe_bake.h"
#endif

namespace dpc::demo {

studio::StudioBake readStudioBake(const std::string& path) {
#ifdef DPC_HAVE_BAKE
  static_assert(bake::kParameterRows == studio::kBakeRows, "rows: the octave bands, broadband");
  const bake::BakeFile file = bake::BakeFile::open(path, bake::BakeFile::Access::kInspect);
  studio::StudioBake b;
  b.file = path;
  b.probes = file.header().probes.positions;
  b.done = file.done();
  b.sources = file.header().shape.sources;
  b.parameters.assign(bake::kParameterNames.begin(), bake::kParameterNames.end());
  b.values = file.readAll("parameters");
  b.ci95 = file.readAll("parameters_ci95");
  b.sti = file.readAll("sti");
  b.stiCi95 = file.readAll("sti_ci95");
  const size_t perProbe = b.sources * size_t(studio::kBakeRows) * b.parameters.size();
  if (b.values.size() != b.probes.size() * perProbe || b.ci95.size() != b.values.size() ||
      b.sti.size() != b.probes.size() * b.sources || b.stiCi95.size() != b.sti.size() ||
      b.done.size() != b.probes.size())
    throw InputError(path, "parameters", "shape does not match the probes and sources");
  return b;
#else
  throw InputError("command line", "--bake",
                   "this dpc-demo was built without HDF5 (scripts/install-deps.sh installs "
                   "libhdf5-dev): cannot read " + path);
#endif
}

}  // namespace dpc::demo
