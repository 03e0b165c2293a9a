#include "engine/path_slits.h"

#include <algorithm>
#include <array>
#include <glm/geometric.hpp>

#include "engine/channel_path.h"
#include "engine/diffraction.h"
#include "engine/gap_probe.h"
#include "engine/surface_bound.h"

namespace dpc {

namespace {

constexpr float kGapFarthest = 16.f;  // m: the widest gap probed (k w = 4 pi at 44 Hz)

/// The distance across a channel's gap, square to its face, at a quarter and three quarters of
/// its depth (m): the far side's when it stands parallel to the face at both (the two within
/// 10 % or 0.5 mm), else -1. The probe
/// reads a gap through its legs, which for a channel seen at a steep angle (a listener beside
/// the doorway, the gap at the far jamb) meet the far side only at a line: a 3 mm gap along a
/// 4 cm leaf read 7.4 mm wide and without depth, 13 dB too loud.
float squareWidth(const Tracer& tracer, const EdgePath& p) {
  std::array<float, 2> w{};
  for (size_t k = 0; k < 2; ++k) {
    SurfaceHit hit;
    const glm::vec3 from = p.q + (k == 0 ? 0.25f : 0.75f) * p.through;
    if (!tracer.intersect(TraceRay{from, p.mouth, surfaceOffset(from), 2.f * p.gapWidth}, hit))
      return -1.f;
    w[k] = hit.t;
  }
  const float wide = std::max(w[0], w[1]);
  return wide - std::min(w[0], w[1]) <= std::max(0.1f * wide, 5e-4f) ? wide : -1.f;
}

/// Path p's slit from the probe's shape of its gap (p.gapWidth > 0).
void setSlit(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
             GapShape shape, EdgePath& p) {
  const float length = glm::length(p.through);
  if (p.measuredDepth && shape.depth >= 0.f) {  // the slit where its far side stands
    const glm::vec3 dir = p.through / length;
    p.q += shape.inset * dir;
    p.through = shape.depth * dir;
  }
  const bool turned = p.before + p.lipBefore + p.beyond + p.lipBeyond != glm::vec3(0.f);
  if (!p.measuredDepth && length > 0.f && (!shape.farSide || shape.depth == 0.f)) {
    // No far side, or one met at a line within the face, by the legs: standing square across
    // the face at both its quarters, it stands along the whole face (a leaf's side in a thick
    // wall's reveal), and the gap is as wide as it is there.
    if (const float w = squareWidth(tracer, p); w > 0.f) {
      p.gapWidth = w;
      shape.farSide = true;
      shape.depth = length;
      shape.inset = 0.f;
    }
  }
  makeSlit(source + p.before + p.lipBefore, L - p.through - p.beyond - p.lipBeyond,
           std::max(shape.from, p.visibleFrom), std::min(shape.to, p.visibleTo), p);
  p.slitAspect = double(shape.aspect);
  if (p.measuredDepth || !(length > 0.f)) return;
  if (!turned && !shape.farSide) {
    // A small body's face with nothing across it (a leaf ajar a few degrees, its side face
    // out of the reveal): the gap is the opening at a mouth, a slit without depth.
    p.slit.depth = 0.0;
  } else if (shape.farSide && shape.depth >= 0.f &&
             (shape.depth > 0.f || (shape.inset > kGapProbeThrough &&
                                    shape.inset < length - kGapProbeThrough))) {
    // Its far side standing along part of the face (a leaf ajar a degree or two, its latch
    // face half out of the reveal), or across it at a line within it (a box leaf in a sheet
    // wall: the slit without depth), not only at a mouth (a reveal whose far side is a leaf's
    // rim at its back edge): the slit as deep as that part, its mouths where found.
    p.slit.depth = std::max(0.0, p.slit.depth - double(length - shape.depth));
    p.farSideAlong = shape.depth > 0.f;
  }
}

/// True when a channel's face has another solid lying on it (a leaf that fills its doorway
/// exactly, its top flush with the lintel's underside, or the reveal beside it): a point
/// kGapNarrowest off the middle of the face lies inside that solid, and the rays from it both
/// ways along the channel meet its faces within a wall's thickness from behind (the normals of
/// a solid wound inside out turned back, SurfaceBodies::outward: staggered posts so wound
/// had every gap between them read covered), or both from the front on one closed body that is
/// not the face's own (a body larger than a solid object whose faces point inward; in a gap
/// between two stops both rays meet the stops from the front, but they are two bodies, or the
/// wall's own). The probe's points across a covered mouth lie in the solid too,
/// and the legs to them, blocked by its faces in front of the mouth, read as another edge's
/// shadow: a sealed leaf's top and sill were taken for gaps 35 mm wide. `closer`: the
/// solid's surface met ahead.
bool coveredFace(const Tracer& tracer, const std::vector<uint32_t>& surfaces,
                 const SurfaceBodies* bodies, EdgePath& p) {
  const float depth = glm::length(p.through);
  if (!(depth > 0.f)) return false;
  const glm::vec3 along = p.through / depth;
  const glm::vec3 m = p.q + 0.5f * p.through + kGapNarrowest * p.mouth;
  const float reach = 0.5f * depth + kChannelDepthMax;
  SurfaceHit ahead, behind;
  if (!tracer.intersect(TraceRay{m, along, 0.f, reach}, ahead) ||
      !tracer.intersect(TraceRay{m, -along, 0.f, reach}, behind))
    return false;
  const uint32_t s = surfaceOf(surfaces, ahead.triangle), t = surfaceOf(surfaces, behind.triangle);
  auto outward = [&](uint32_t u) {  // a solid wound inside out: its normals turned back
    return bodies && u < bodies->body.size() ? bodies->outward[bodies->body[u]] : 1.f;
  };
  const float a = outward(s) * glm::dot(ahead.normal, along);
  const float b = -outward(t) * glm::dot(behind.normal, along);
  bool covered = a > 0.f && b > 0.f;
  if (!covered && a < 0.f && b < 0.f && bodies && s < bodies->body.size() &&
      t < bodies->body.size()) {
    const uint32_t body = bodies->body[s];
    covered = body == bodies->body[t] && bodies->closed[body] &&
              !onEdgeBody(bodies->body, *p.edge, s);
  }
  if (covered) p.gapCloser = s;
  return covered;
}

}  // namespace

void findSlits(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
               const std::vector<uint32_t>& surfaces, std::vector<EdgePath>& paths,
               std::vector<EdgePath>& closed, const SurfaceBodies* bodies) {
  size_t open = 0;
  for (size_t j = 0; j < paths.size(); ++j) {
    if (coveredFace(tracer, surfaces, bodies, paths[j]))
      closed.push_back(paths[j]);
    else
      paths[open++] = paths[j];
  }
  paths.resize(open);
  std::vector<GapProbe> probes(paths.size());
  for (size_t j = 0; j < paths.size(); ++j) {
    const EdgePath& p = paths[j];
    const DiffractionEdge& e = *p.edge;
    const float t = glm::dot(p.q - e.a, e.direction);
    const float reach = std::min(e.length / float(kSlitMinAspect), kGapFarthest);
    probes[j] = {p.q,    p.mouth,  reach,      e.direction, -t,
                 e.length - t, e.face0, p.turn, p.airWedge, p.through,
                 p.before + p.lipBefore != glm::vec3(0.f),
                 p.beyond + p.lipBeyond != glm::vec3(0.f)};
  }
  std::vector<GapShape> shapes(paths.size());
  probeGaps(tracer, source, L, probes, shapes);
  size_t kept = 0;
  for (size_t j = 0; j < paths.size(); ++j) {
    if (shapes[j].closer != kNoCloser) paths[j].gapCloser = surfaceOf(surfaces, shapes[j].closer);
    if (shapes[j].width < 0.f) {
      closed.push_back(paths[j]);
      continue;
    }
    EdgePath& p = paths[kept++] = paths[j];
    p.gapWidth = shapes[j].width;
    if (p.gapWidth > 0.f) setSlit(tracer, source, L, shapes[j], p);
  }
  paths.resize(kept);
  markSlitOwners(paths);
}

}  // namespace dpc
