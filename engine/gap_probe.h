// How wide is the gap an edge path passes through? An edge path source -> Q -> listener that
// runs between its edge and another surface a few millimetres away (a door frame's edge next
// to the closed leaf, a partition's rim above the floor) passes a slit, not a free edge: the
// edge's UTD field assumes nothing else within several wavelengths of Q (engine/slit.h models
// the slit). The probe moves Q across the mouth of the gap, P = Q + delta u, and asks whether
// both straight legs source -> P and listener -> P are free, each run a little past P (up to
// kGapProbeThrough, at most delta, never into the edge's own solid) so that a surface lying in
// P's own plane (a leaf flush with the wall: zero-thickness sheets are the common case, and a
// ray in a sheet's plane misses it) blocks them. The width is the
// first delta that is blocked: eight deltas spaced evenly in log from kGapNarrowest to the
// probe's reach, then eight between the last free and the first blocked one (width within
// 12 % of the gap's; the slit model depends on the width through its logarithm).
//
// u must point across the gap, away from the edge's own solid, in the plane perpendicular to
// the edge; for a lone wedge a free u exists (the bisector of the region both the source and
// the listener see beyond Q: engine/diffraction.cpp chooses it), so a free edge is never
// mistaken for a slit.
//
// Threads: any thread that may query the tracer (reentrant: concurrent calls are safe).
// Allocates its ray batches. No errors.
#pragma once

#include <glm/vec3.hpp>
#include <span>

#include "engine/tracer.h"

namespace dpc {

/// Narrowest gap told apart from a closed one, m (narrower: closed, width -1).
inline constexpr float kGapNarrowest = 5e-4f;
/// How far each probe leg runs past the probe point, m.
inline constexpr float kGapProbeThrough = 2e-3f;

/// One edge path's gap: its point Q on the edge, the unit direction u across the gap's mouth,
/// the widest gap looked for (m), and the edge's own solid, which the legs' short runs past P
/// must not enter (near a wedge's apex they would): seen along the edge, the air wedge spans
/// airWedge radians from face0 turning toward `turn` (unit vectors across the edge); the rest
/// is solid (none for a sheet's rim, airWedge 2 pi).
struct GapProbe {
  glm::vec3 q{0.f};
  glm::vec3 mouth{0.f};
  float reach = 0.f;
  glm::vec3 face0{0.f}, turn{0.f};
  float airWedge = 0.f;
};

/// Per probe, the gap's width in metres: 0 when nothing closes it within reach (a free edge),
/// -1 when it is closed within kGapNarrowest, else the width (the geometric mean of the last
/// free and the first blocked delta). widths.size() >= probes.size(). Two batch queries of
/// 16 rays per probe at most.
void probeGapWidths(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
                    std::span<const GapProbe> probes, std::span<float> widths);

}  // namespace dpc
