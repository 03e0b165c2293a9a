#include "engine/channel_path.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <utility>

#include "engine/channel_turn.h"

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

/// The unit direction from `front` out of the channel's face into the gap beside it: away
/// from front's other face, square to the face (none: zero).
glm::vec3 channelMouth(const DiffractionEdge& front, const glm::vec3& m) {
  const std::array<glm::vec3, 2> faces = faceDirections(front);
  const glm::vec3 other = glm::dot(faces[0], m) > glm::dot(faces[1], m) ? faces[1] : faces[0];
  const glm::vec3 u = -(other - glm::dot(other, m) * m);
  const float l = glm::length(u);
  return l > 0.5f ? u / l : glm::vec3(0.f);
}

}  // namespace

glm::vec3 acrossTo(const DiffractionEdge& a, const DiffractionEdge& b) {
  const glm::vec3 v = b.a - a.a;
  return v - glm::dot(v, a.direction) * a.direction;
}

std::vector<NarrowFace> narrowFaces(const std::vector<DiffractionEdge>& edges,
                                    const std::vector<std::vector<uint32_t>>& surfaceEdges) {
  std::vector<NarrowFace> out;
  for (const std::vector<uint32_t>& list : surfaceEdges)
    for (size_t i = 0; i < list.size(); ++i)
      for (size_t j = i + 1; j < list.size(); ++j) {
        const DiffractionEdge &a = edges[list[i]], &b = edges[list[j]];
        if (isFreeEdge(a) || isFreeEdge(b) || glm::length(acrossTo(a, b)) > kChannelDepthMax ||
            !joinedByFace(a, b))
          continue;
        out.push_back({std::min(list[i], list[j]), std::max(list[i], list[j])});
      }
  std::sort(out.begin(), out.end(),
            [](const NarrowFace& x, const NarrowFace& y) { return std::pair(x.a, x.b) < std::pair(y.a, y.b); });
  out.erase(std::unique(out.begin(), out.end(),
                        [](const NarrowFace& x, const NarrowFace& y) { return x.a == y.a && x.b == y.b; }),
            out.end());
  setChannelNeighbours(edges, out);
  return out;
}

namespace {

/// The point Q1 on `front` of least length source -> Q1 -> Q1 + through -> L (Fermat over the
/// front edge with the listener moved back across the face), as its parameter along front (m);
/// NaN when the source or the moved listener lies on the edge's line.
float channelPoint(const DiffractionEdge& front, const glm::vec3& through, const glm::vec3& source,
                   const glm::vec3& L) {
  const glm::vec3 ps = source - front.a, pl = L - through - front.a;
  const float ts = glm::dot(ps, front.direction), tl = glm::dot(pl, front.direction);
  const float rs = glm::length(ps - ts * front.direction), rl = glm::length(pl - tl * front.direction);
  if (!(rs > 1e-4f) || !(rl > 1e-4f)) return std::numeric_limits<float>::quiet_NaN();
  return ts + (tl - ts) * rs / (rs + rl);
}

/// The air wedge at `front` (airWedge) holding the source and the mouth, into p's angles (the
/// mouth's as the listener's: no UTD field, any angle inside keeps the terms finite); false
/// unless it is convex and holds the mouth.
bool channelWedge(const DiffractionEdge& front, const glm::vec3& q, const glm::vec3& source,
                  const glm::vec3& mouth, EdgePath& p, double& sense) {
  return airWedge(front, q, source, q + mouth, p.phiS, p.phiL, p.wedge, sense);
}

}  // namespace

bool channelVia(const DiffractionEdge& front, const DiffractionEdge& back,
                const ChannelTurns& turns, const glm::vec3& source, const glm::vec3& L,
                EdgePath& p, float at) {
  const glm::vec3 before = turns.before + turns.lipBefore;  // to the outer legs' ends
  const glm::vec3 beyond = turns.beyond + turns.lipBeyond;
  const glm::vec3 through = acrossTo(front, back);
  const float depth = glm::length(through);
  if (!(depth > 1e-4f)) return false;
  const glm::vec3 m = through / depth;
  if (!(glm::dot(source - front.a, m) < 0.f) || !(glm::dot(L - back.a, m) > 0.f)) return false;
  const float t =
      std::isnan(at) ? channelPoint(front, through + beyond, source + before, L) : at;
  const glm::vec3 q = front.a + t * front.direction;
  const float tb = glm::dot(q + through - back.a, back.direction);
  if (!(t > 0.f && t < front.length && tb > 0.f && tb < back.length)) return false;
  const glm::vec3 mouth = channelMouth(front, m);
  const glm::vec3 exit = q + through + beyond;
  const float r = glm::distance(source, q - before), s = glm::distance(exit, L);
  p = EdgePath{};
  double sense = 1.0;
  if (mouth == glm::vec3(0.f) || !channelWedge(front, q, source, mouth, p, sense) ||
      !(r > kLegEpsilon && s > kLegEpsilon))
    return false;
  p.length = double(r) + double(turns.lipBeforeLength) + double(glm::length(turns.before)) +
             double(depth) + double(glm::length(turns.beyond)) + double(turns.lipBeyondLength) +
             double(s);
  p.distanceParameter = double(r) * double(s) / (double(r) + double(s));
  p.spreading = 0.0;  // no UTD field: the slit's only
  p.prefactor = utdPrefactor(p.wedge / kPi, 1.0);
  setTerms(false, p);
  p.legs = float(p.length);
  p.arrival = (exit - L) / s;
  p.leaving = (q - before - source) / r;
  p.edge = &front;
  p.q = q;
  p.mouth = mouth;
  p.turn = float(sense) * front.normal0;
  p.airWedge = float(p.wedge);
  p.share = 0.0;
  p.atEnd = true;
  p.through = through;
  p.beyond = turns.beyond;
  p.before = turns.before;
  p.lipBeyond = turns.lipBeyond;
  p.lipBefore = turns.lipBefore;
  const glm::vec3 entry = q - turns.before, exitMouth = q + through + turns.beyond;
  p.lipLength = {turns.lipBeforeLength, turns.lipBeyondLength};
  p.legWidth = {turns.beforeWidth, turns.beyondWidth};
  p.lipExcess = {std::max(0.f, turns.lipBeforeLength + r - glm::distance(source, entry)),
                 std::max(0.f, turns.lipBeyondLength + s - glm::distance(exitMouth, L))};
  p.face = front.surfaces[0] == back.surfaces[0] || front.surfaces[0] == back.surfaces[1]
               ? front.surfaces[0]
               : front.surfaces[1];
  return true;
}

bool channelPath(const DiffractionEdge& front, const DiffractionEdge& back,
                 const glm::vec3& source, const glm::vec3& L, EdgePath& p, float at) {
  return channelVia(front, back, ChannelTurns{}, source, L, p, at);
}

}  // namespace dpc

namespace dpc {

bool gapAcross(const Tracer& tracer, const DiffractionEdge& front, const glm::vec3& through,
               float t) {
  const float near = std::clamp(t, 0.01f * front.length, 0.99f * front.length);
  const glm::vec3 from = front.a + near * front.direction;
  const glm::vec3 mouth = channelMouth(front, through / glm::length(through));
  if (mouth == glm::vec3(0.f)) return false;
  const glm::vec3 back = from + through;
  return tracer.occluded(TraceRay{from, mouth, surfaceOffset(from), kChannelDepthMax}) ||
         tracer.occluded(TraceRay{back, mouth, surfaceOffset(back), kChannelDepthMax});
}

bool visibleChannel(const Tracer& tracer, const DiffractionEdge& front, const DiffractionEdge& back,
                    const glm::vec3& source, const glm::vec3& L, EdgePath& p) {
  constexpr int kSamples = 8, kSteps = 8;
  const glm::vec3 through = acrossTo(front, back);
  if (!(glm::dot(source - front.a, through) < 0.f) || !(glm::dot(L - back.a, through) > 0.f))
    return false;
  const float stationary = channelPoint(front, through, source, L);
  if (std::isnan(stationary) || !gapAcross(tracer, front, through, stationary)) return false;
  auto freeAt = [&](float t, EdgePath& out) {
    return channelPath(front, back, source, L, out, t) && legsFree(tracer, source, L, out);
  };
  float best = std::numeric_limits<float>::quiet_NaN();  // the free sample nearest stationary
  for (int i = 0; i < kSamples; ++i) {
    const float t = front.length * (float(i) + 0.5f) / float(kSamples);
    EdgePath candidate;
    if ((std::isnan(best) || std::abs(t - stationary) < std::abs(best - stationary)) &&
        freeAt(t, candidate)) {
      best = t;
      p = candidate;
    }
  }
  if (std::isnan(best)) return false;
  // Where the legs stop being free between it and the point of least length (bisection): the
  // slit radiates from the visible side of that limit only.
  float lo = best, hi = std::clamp(stationary, 0.f, front.length);
  for (int i = 0; i < kSteps; ++i) {
    const float mid = 0.5f * (lo + hi);
    EdgePath probe;
    (freeAt(mid, probe) ? lo : hi) = mid;
  }
  (stationary > best ? p.visibleTo : p.visibleFrom) = lo - best;
  return true;
}

bool segmentFree(const Tracer& tracer, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 v = b - a;
  const float length = glm::length(v);
  return length > 2.f * kLegEpsilon &&
         !tracer.occluded(TraceRay{a, v / length, kLegEpsilon, length - kLegEpsilon});
}

bool narrowAt(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a,
              const glm::vec3& b, float t) {
  const glm::vec3 n = glm::normalize(glm::cross(glm::normalize(b - a), along));
  const glm::vec3 at = a + t * (b - a);
  return tracer.occluded(TraceRay{at, n, 0.f, kChannelGapMax}) &&
         tracer.occluded(TraceRay{at, -n, 0.f, kChannelGapMax});
}

float narrowWidth(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a,
                  const glm::vec3& b, float t) {
  const glm::vec3 n = glm::normalize(glm::cross(glm::normalize(b - a), along));
  const glm::vec3 at = a + t * (b - a);
  SurfaceHit front, back;
  if (!tracer.intersect(TraceRay{at, n, 0.f, kChannelGapMax}, front) ||
      !tracer.intersect(TraceRay{at, -n, 0.f, kChannelGapMax}, back))
    return std::numeric_limits<float>::infinity();
  // Each surface's distance from the point square to itself: a leg that crosses the gap
  // aslant (from the leaf's corner to the stop's edge) would read it wider along n.
  return front.t * std::abs(glm::dot(n, front.normal)) + back.t * std::abs(glm::dot(n, back.normal));
}

}  // namespace dpc
