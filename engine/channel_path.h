// A gap with depth: the channel between a box leaf's side face and the reveal, frame or floor
// beside it. Its two edges (the leaf's front and back rims of that face) each shut the other
// out: from the front edge the listener lies inside the leaf, and from the back edge the
// source does, so no first-order edge path passes the gap, and a closed box leaf in a thick
// wall passed nothing at all. The channel path runs source -> Q1 on the front edge, along the
// face to Q2 = Q1 + through on the back edge, -> listener, with Q1 where r + |through| + s is
// least (the listener moved back by `through` makes it a first-order path over the front
// edge). It carries only its slit's field (engine/slit.h), with the face's width as the slit's
// depth d (more where it turns round a door stop: engine/edge_path.h channelDepth,
// engine/channel_turn.h): the transmission-line model of Gomperts (1964) and Mechel (1986)
// through a slit of that depth, found and measured by engine/gap_probe.h from both mouths.
//
// Internal to the engine (engine/diffraction.cpp). Any thread; allocates only the pairs at
// load time; no errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <vector>

#include "engine/edge_path.h"
#include "engine/tracer.h"

namespace dpc {

/// m: the widest face a channel runs along (door leaves are 35 to 80 mm thick; a thin wall's
/// reveal).
inline constexpr float kChannelDepthMax = 0.3f;

/// m: the widest gap taken for a narrow one where its width is not probed (a leg between two
/// surfaces, a turned channel's legs and its mouth's opening, the face being shallower than
/// this: a 6 mm glass leaf with 10 mm gaps). A channel whose gap the probe measures across its
/// face carries it at any width (engine/diffraction.cpp keepOpenChannels).
inline constexpr float kChannelGapMax = 0.03f;

/// The narrow faces (NarrowFace, engine/diffraction.h: two edges bounding one flat face at most
/// kChannelDepthMax wide, joinedByFace, neither a sheet's rim), each pair once, looked for among the edges on each flat surface
/// (`surfaceEdges`: SurfaceBodies::edges).
std::vector<NarrowFace> narrowFaces(const std::vector<DiffractionEdge>& edges,
                                    const std::vector<std::vector<uint32_t>>& surfaceEdges);

/// The offset from edge a's line to edge b's, perpendicular to a (m).
glm::vec3 acrossTo(const DiffractionEdge& a, const DiffractionEdge& b);

/// The channel path from source over `front` and along the face to `back`, then to the
/// listener L, without its gap (findSlits probes it); false unless the source lies on front's
/// side of the face and L on back's, the point of least length lies on both edges, and the
/// face's outer side is an air wedge wider than pi at front. p's UTD share is 0 (atEnd): only
/// its slit's field counts.
/// With `at` (m along front), the path through that point of front instead of the point of
/// least length.
bool channelPath(const DiffractionEdge& front, const DiffractionEdge& back,
                 const glm::vec3& source, const glm::vec3& L, EdgePath& p,
                 float at = std::numeric_limits<float>::quiet_NaN());

/// A channel's legs past its mouths when it turns there (engine/channel_turn.h), m: the
/// narrow leg from the front mouth's point Q back to where it enters (Q - before) and from the
/// back mouth's point on to where it leaves (+ beyond), each a continuation of the slit; then
/// the free legs round the stop to where the source and the listener are seen (lipBefore,
/// lipBeyond: the offsets; their lengths, one leg or several round successive corners).
struct ChannelTurns {
  glm::vec3 before{0.f}, beyond{0.f};
  glm::vec3 lipBefore{0.f}, lipBeyond{0.f};
  float lipBeforeLength = 0.f, lipBeyondLength = 0.f;
  float beforeWidth = 0.f, beyondWidth = 0.f;  ///< m: the narrow legs' widths (narrowWidth)
};

/// channelPath entered at Q - before - lipBefore and left at Q + through + beyond + lipBeyond:
/// the point of least length with the source moved on and the listener back by those offsets
/// (the legs' lengths as given), the path's fields set (EdgePath::before, beyond, lipBefore,
/// lipBeyond, face). Legs not tested.
bool channelVia(const DiffractionEdge& front, const DiffractionEdge& back,
                const ChannelTurns& turns, const glm::vec3& source, const glm::vec3& L,
                EdgePath& p, float at = std::numeric_limits<float>::quiet_NaN());

/// True when a ray from `front` near parameter t (m along it) across the channel's mouth meets
/// the gap's other side within kChannelDepthMax (a seat's narrow faces have none: no channel is
/// looked for), or the same ray from the back edge does (a leaf opened a degree or two: its
/// side face's front corner has left the reveal, the back of the face still runs beside it).
/// One or two rays.
bool gapAcross(const Tracer& tracer, const DiffractionEdge& front, const glm::vec3& through,
               float t);

/// For a channel whose point of least length is hidden or lies beyond its edges (a lintel hides
/// the side gaps' upper part from a listener above the door): p becomes the path through the
/// free point of 8 along front nearest that point, its slit limited on that side to where the
/// legs stop being free (p.visibleFrom or p.visibleTo, by 8 bisections), so the slit's line
/// source counts only its visible part (engine/slit.h integrates over the slit's extent). False
/// when the source and the listener are not on the face's two sides or no sampled point is
/// free. Reentrant; 2 rays per point tried.
bool visibleChannel(const Tracer& tracer, const DiffractionEdge& front, const DiffractionEdge& back,
                    const glm::vec3& source, const glm::vec3& L, EdgePath& p);

/// True when the segment from a to b meets nothing (its ends, on edges, kept clear by
/// kLegEpsilon). One ray.
bool segmentFree(const Tracer& tracer, const glm::vec3& a, const glm::vec3& b);

/// True when the segment from a to b passes, at the fraction t (0 to 1) of its length, between
/// two surfaces (a leaf's face and the stop's): from that point, square to it and to the
/// edges' direction `along`, both sides are closed within kChannelGapMax. Two rays.
bool narrowAt(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a,
              const glm::vec3& b, float t);

/// The width there of the gap narrowAt finds (m: the two surfaces' distances from that point,
/// each square to its surface, summed), +inf where it finds none. Two closest-hit rays.
float narrowWidth(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a,
                  const glm::vec3& b, float t);

}  // namespace dpc
