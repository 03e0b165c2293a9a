// How wide is the gap an edge path passes through? An edge path source -> Q -> listener that runs
// between its edge and another surface a few millimetres away (a door frame's edge next to the
// closed leaf, a partition's rim above the floor) passes a slit, not a free edge: the edge's UTD
// field assumes nothing else within several wavelengths of Q (engine/slit.h models the slit). The
// probe moves Q across the mouth of the gap, P = Q + delta u, and asks whether both straight legs
// source -> P and listener -> P are free, each run a little past P (up to kGapProbeThrough, at most
// P's distance from the edge, never into the edge's own solid) so that a surface lying in P's own
// plane (a leaf flush with the wall: zero-thickness sheets are the common case, and a ray in a
// sheet's plane misses it) blocks them. The width is the first delta that is blocked after a free
// one: four deltas spaced evenly in log from kGapNarrowest to the probe's reach (every path: 8
// rays), then, for a gap, the means of the free ones below it (a gap may close and open again
// across its mouth: a sheet's rim in front of a wall passes the wall's corner, then meets its far
// face, too far out to close it; up to 2 more points), then twice eight between the last free and
// the first blocked one (the width is the geometric mean of the two deltas that bracket it, within
// 5 % of either for reaches up to 16 m; the slit model depends on the width through its logarithm).
// A slit must also run along the edge: the same test 1 to 4 widths either side of Q along the edge,
// free at 0.5 w across the mouth (or where Q's mouth was found free just short of w: met at a
// slant, a leaf ajar hides the mouth's middle from the listener) and blocked at 1.2 or 1.5 w, gives
// the length over which the gap stays that narrow (up to 8 widths; a small obstacle in a wide
// opening is no slit), and by bisection where it ends either side of Q, the slit's length (a leaf
// shorter than its frame's edge leaves a slit only along the leaf; taken as the edge's whole
// length, a partition meshed with its jambs running past the lintel put a door with 20 mm gaps
// above the open doorway at 63 Hz). Where Q's mouth is free, it may open onto a narrow gap that
// crosses the edge at Q (the slit between two door leaves, right under the lintel's point of least
// path length): the mouth 4 cm either side of Q along the edge decides, closed on both sides (no
// gap: what passes there is the crossing gap's) or a gap on both sides (its width), 16 more rays
// per free path.
//
// A channel (a gap along a box leaf's side face, between its front and back edges) is probed
// at its front mouth from the source and at its back mouth from the listener; where it turns
// at a mouth (against a door stop), that mouth's leg is not probed.
//
// u must point across the gap, away from the edge's own solid, in the plane perpendicular to
// the edge, into the angles around the edge that both the source and the listener see
// (engine/diffraction.cpp chooses it), so that a lone wedge never closes it.
//
// Threads: any thread that may query the tracer (reentrant: concurrent calls are safe).
// Allocates its ray batches. No errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <span>

#include "engine/tracer.h"

namespace dpc {

/// Narrowest gap told apart from a closed one, m (narrower: closed, width -1).
inline constexpr float kGapNarrowest = 5e-4f;
/// How far each probe leg runs past the probe point, m.
inline constexpr float kGapProbeThrough = 2e-3f;

/// One edge path's gap: its point Q on the edge, the unit direction u across the gap's mouth,
/// the widest gap looked for (m), the edge's unit direction and its ends relative to Q (m
/// along it: from <= 0 <= to), and the edge's own solid, which the legs' short runs past P
/// must not enter (near a wedge's apex they would): seen along the edge, the air wedge spans
/// airWedge radians from face0 turning toward `turn` (unit vectors across the edge); the rest
/// is solid (none for a sheet's rim, airWedge 2 pi).
struct GapProbe {
  glm::vec3 q{0.f};
  glm::vec3 mouth{0.f};
  float reach = 0.f;
  glm::vec3 along{0.f};
  float from = 0.f, to = 0.f;
  glm::vec3 face0{0.f}, turn{0.f};
  float airWedge = 0.f;
  /// A channel's depth (engine/channel_path.h): the listener's legs go to each point moved by
  /// this (m), to the channel's back mouth, and stop there; zero for an edge's own gap.
  glm::vec3 through{0.f};
  /// A channel that turns before its front mouth or past its back one (engine/channel_turn.h
  /// turnedChannel): the source's or the listener's legs are not tested (each was found free
  /// from the turn's edge, and the mouth itself faces the door stop).
  bool turnedIn = false, turnedOut = false;
};

/// No triangle: a gap's other side not found.
inline constexpr uint32_t kNoCloser = 0xffffffffu;

/// What the probe found: the gap's width (m; 0 when nothing closes it within reach, a free
/// edge; -1 when every delta is blocked, a gap closed within kGapNarrowest; else the geometric
/// mean of the last free and the first blocked delta after the first free one) and, for a gap,
/// the length along the edge over which it stays open at 0.5 widths or at `open` and closed
/// within 1.5 widths, in widths (0 to 8, in steps of 1), and where it ends along the edge either
/// side of Q (m, relative to Q along `along`: from <= 0 <= to), found to within 1/256 of the
/// edge's length on that side.
/// `closer`: for a gap or a closed one, the triangle (the Tracer's numbering) whose surface
/// closes it, met at the first closed delta; else kNoCloser.
struct GapShape {
  float width = 0.f;
  float aspect = 0.f;
  float from = 0.f, to = 0.f;
  uint32_t closer = kNoCloser;
  /// The widest delta found free below the width at Q (m; 0 where not measured): a mouth met at
  /// a slant may be hidden half a width across (a leaf ajar hides it from the listener just
  /// inside its rim) and open again just short of the width.
  float open = 0.f;
  /// A channel's depth where its far side stands (m; a leaf 4 cm thick beside a 0.2 m reveal:
  /// 0.04), and how far in from the front mouth that begins (m); depth -1 for other probes.
  float depth = -1.f;
  float inset = 0.f;
  /// A channel gap's far side met beside the face from either mouth (measureDepths' rays);
  /// false when nothing stands across the face within 1.5 widths (a leaf ajar, its side face
  /// out of the reveal: the gap is the opening at a mouth, with no depth).
  bool farSide = true;
};

/// Probes every gap; shapes.size() >= probes.size(). Batch queries: 8 rays per probe, 16
/// more per probe free at Q (its flanks), then 16, 16, 32 and 9 x 8 (its ends) per gap found.
void probeGaps(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
               std::span<const GapProbe> probes, std::span<GapShape> shapes);

}  // namespace dpc
