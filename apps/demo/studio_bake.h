// dpc-demo --studio --bake BAKE.h5: the bake's probe grid and parameter maps for the page
// (/api/bake, docs/studio.md), read once from the file dpc-demo already plays from.
#pragma once

#include <string>

#include "apps/studio/studio_json.h"

namespace dpc::demo {

/// The probes (positions, done mask), the source count and every probe's parameters and STI
/// with their 95 % half-widths (the datasets bake/parameter_map.cpp writes as CSV), read with
/// BakeFile::Access::kInspect: a damaged probe counts as not done. Throws InputError naming the
/// file for a bake that does not open, and naming --bake when dpc-demo was built without HDF5.
/// Control thread; allocates (reads the whole file once, as its verification does).
studio::StudioBake readStudioBake(const std::string& path);

}  // namespace dpc::demo
