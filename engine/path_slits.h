// The slit each edge path passes: the gap probe's width, extent and far side (engine/gap_probe.h)
// made into the path's slit (engine/edge_path.h makeSlit, engine/slit.h).
//
// Internal to the engine (engine/diffraction.cpp and the passes it calls). Any thread
// (reentrant: tracer queries only); allocates the probes' batches; no errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "engine/edge_path.h"
#include "engine/tracer.h"

namespace dpc {

struct SurfaceBodies;

/// Looks for the gap each path may pass (engine/gap_probe.h) and sets its slit and the surface
/// that closes it (`surfaces`: per mesh triangle, its flat surface); moves the paths whose gap
/// is closed (narrower than kGapNarrowest, or a channel whose face another solid lies on:
/// `bodies`, when given, tells a closed body whose faces point inward) to closed, then settles
/// who carries each slit (markSlitOwners). source and L in m.
void findSlits(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
               const std::vector<uint32_t>& surfaces, std::vector<EdgePath>& paths,
               std::vector<EdgePath>& closed, const SurfaceBodies* bodies = nullptr);

}  // namespace dpc
