#include "engine/edge_chain.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <numbers>
#include <utility>

#include "engine/channel_path.h"
#include "engine/edge_grid.h"
#include "engine/edge_path.h"
#include "engine/hull_ways.h"

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

/// radians: how far outside its air wedge, or short of its shadow boundary, a chain's point may
/// lie (a leg along a face lies on the wedge's side).
constexpr double kWrapTolerance = 1e-3;

/// The point of edge e's line at `along` (m) measured along the unit direction d.
glm::vec3 pointAlong(const DiffractionEdge& e, const glm::vec3& d, float along) {
  const float rate = glm::dot(e.direction, d);
  return e.a + ((along - glm::dot(e.a, d)) / rate) * e.direction;
}

/// Lays the chain over `ids` (n edges parallel to the first) out at its point of least length
/// from source to L: unfolded about the edges, the path runs straight, so each Q lies along
/// the edges as far as its share of the path's length across them. False when a Q falls off
/// its edge by more than `reach` (m); within it, Q is laid just inside the edge's end (a way
/// over a row of slats' tops whose point falls in a slot between two: the row's top edge is
/// a dashed one, whole at wavelengths longer than its gaps).
bool layChain(const std::vector<DiffractionEdge>& edges,
              const std::array<uint32_t, kChainEdges>& ids, size_t n, const glm::vec3& source,
              const glm::vec3& L, EdgeChain& c, float reach) {
  const glm::vec3 d = edges[ids[0]].direction;
  auto across = [&](const glm::vec3& x) { return x - glm::dot(x, d) * d; };
  const float s = glm::dot(source, d), run = glm::dot(L, d) - s;
  std::array<glm::vec3, kChainEdges + 2> p;
  p[0] = across(source);
  for (size_t i = 0; i < n; ++i) p[i + 1] = across(pointAlong(edges[ids[i]], d, s + 0.5f * run));
  p[n + 1] = across(L);
  std::array<float, kChainEdges + 2> cumulative{};
  for (size_t i = 1; i < n + 2; ++i)
    cumulative[i] = cumulative[i - 1] + glm::distance(p[i - 1], p[i]);
  const float total = cumulative[n + 1];
  if (!(total > 0.f)) return false;
  c.n = n;
  c.length = 0.f;
  c.ends = {edges[ids[0]], edges[ids[n - 1]]};
  glm::vec3 last = source;
  for (size_t i = 0; i < n; ++i) {
    const DiffractionEdge& e = edges[ids[i]];
    c.edge[i] = ids[i];
    c.q[i] = pointAlong(e, d, s + run * cumulative[i + 1] / total);
    if (!withinEdge(e, c.q[i])) {
      const float t = glm::dot(c.q[i] - e.a, e.direction), inside = std::min(1e-3f, e.length / 4);
      if (t < -reach || t > e.length + reach) return false;
      c.q[i] = e.a + std::clamp(t, inside, e.length - inside) * e.direction;
    }
    c.length += glm::distance(last, c.q[i]);
    last = c.q[i];
  }
  c.length += glm::distance(last, L);
  return true;
}

/// The angles (radians) of `before` and `after` about edge e at q, measured in its wider wedge
/// from its face (a point on that face near 0); false unless that wedge is wider than pi (a
/// convex corner) and holds both (a point on a face, a leg along it, lies in both wedges).
bool widerWedgeAngles(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& before,
                      const glm::vec3& after, double& b, double& a) {
  const bool reversed = double(e.open) < kPi;  // the wider wedge is measured from face 0 back
  const double wedge = reversed ? 2.0 * kPi - double(e.open) : double(e.open);
  auto angleOf = [&](const glm::vec3& x) {
    double t = faceAngle(e, q, x);
    if (reversed) t = 2.0 * kPi - t;
    return t > 2.0 * kPi - kWrapTolerance ? t - 2.0 * kPi : t;  // on face 0: near 0
  };
  b = angleOf(before);
  a = angleOf(after);
  auto inside = [&](double x) { return x > -kWrapTolerance && x < wedge + kWrapTolerance; };
  return wedge > kConvexWedge && inside(a) && inside(b);
}

/// True when the path from `before` to `after` wraps round edge e at q: its wider wedge holds
/// both, on either side of before's shadow boundary. A sheet's rim has a face on either side of
/// its plane: a point in that plane (a hinge jamb, on the line of its leaf ajar) lies on
/// either, and the path round the rim from the face the other point does not see wraps it.
bool wrapsRound(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& before,
                const glm::vec3& after) {
  double b, a;
  if (!widerWedgeAngles(e, q, before, after, b, a)) return false;
  if (std::abs(a - b) > kPi - kWrapTolerance) return true;
  const bool sheet = double(e.open) > 2.0 * kPi - kWrapTolerance;
  auto inPlane = [](double x) { return std::abs(x) < kWrapTolerance; };
  return sheet && (inPlane(a) || inPlane(b));
}

/// True when the straight line from `before` to `after` passes edge e (at q) on its lit side:
/// its wider wedge holds both, within pi of each other.
bool clearsOnLitSide(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& before,
                     const glm::vec3& after) {
  double b, a;
  return widerWedgeAngles(e, q, before, after, b, a) && std::abs(a - b) <= kPi - kWrapTolerance;
}

/// The chain's points: source, its Q, L.
std::array<glm::vec3, kChainEdges + 2> chainPoints(const EdgeChain& c, const glm::vec3& source,
                                                   const glm::vec3& L) {
  std::array<glm::vec3, kChainEdges + 2> p;
  p[0] = source;
  for (size_t i = 0; i < c.n; ++i) p[i + 1] = c.q[i];
  p[c.n + 1] = L;
  return p;
}

/// The chain's geometry: every Q wraps its edge.
bool wrapsAll(const std::vector<DiffractionEdge>& edges, const EdgeChain& c,
              const std::array<glm::vec3, kChainEdges + 2>& p) {
  for (size_t i = 0; i < c.n; ++i)
    if (!wrapsRound(edges[c.edge[i]], c.q[i], p[i], p[i + 2])) return false;
  return true;
}

/// True when the segment from a to b threads a gap at most kChannelGapMax wide: a parallel
/// segment that far to one side (`bothSides`: to each side), square to it and to the edges
/// (direction `along`), is blocked. A leg between two edges may run along a face: the
/// segment on that side lies inside the solid, free unless the solid is thinner, and a leaf
/// beside the reveal the leg runs along blocks the other. A leg to the source or the listener
/// leaves a corner whose own faces block the segment on their side: only both sides blocked
/// (a leaf's side face and the reveal beyond the gap between them) is a gap.
bool threadsGap(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a,
                const glm::vec3& b, bool bothSides) {
  const glm::vec3 n = glm::normalize(glm::cross(b - a, along));
  int blocked = 0;
  for (float side : {1.f, -1.f})
    blocked += !segmentFree(tracer, a + side * kChannelGapMax * n, b + side * kChannelGapMax * n);
  return bothSides ? blocked == 2 : blocked > 0;
}

/// The side of the segment from a to b (+1 along n = (b - a) x along, -1 against it) on which
/// edge e's solid lies (its faces' bisector); 0 where that is unclear (a leg along its face).
float solidSide(const DiffractionEdge& e, const glm::vec3& along, const glm::vec3& a,
                const glm::vec3& b) {
  const glm::vec3 n = glm::normalize(glm::cross(b - a, along));
  const std::array<glm::vec3, 2> faces = faceDirections(e);
  const float s = glm::dot(faces[0] + faces[1], n);
  return std::abs(s) < 1e-3f ? 0.f : std::copysign(1.f, s);
}

/// threadsGap on one side, or, where the solids the segment passes lie on one side of it
/// (`solid`, solidSide: the way round a body, or along a row of posts in line), on the other
/// side only: on theirs the parallel segment runs inside them and across the slots between
/// bodies in a row, which the way along the row's side does not thread.
bool gapBeside(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a, const glm::vec3& b,
               float solid) {
  if (solid == 0.f) return threadsGap(tracer, along, a, b, false);
  const glm::vec3 air = -solid * kChannelGapMax * glm::normalize(glm::cross(b - a, along));
  return !segmentFree(tracer, a + air, b + air);
}

/// True when the leg from q (on an edge) toward `end` passes, within kChannelDepthMax of q,
/// through a gap at most kChannelGapMax wide: the parallel segments either side blocked
/// (threadsGap), or both sides closed across it a few millimetres to centimetres from q (a gap
/// between a leaf and the stop it closes against, whose sides' solids the parallel segments
/// pass inside).
bool outerLegInGap(const Tracer& tracer, const glm::vec3& along, const glm::vec3& q,
                   const glm::vec3& end) {
  const float length = glm::distance(q, end);
  const float reach = std::min(length, kChannelDepthMax);
  const glm::vec3 far = q + (reach / length) * (end - q);
  // The parallel segments start kChannelGapMax along the leg: from q itself, the one on the
  // edge's own side starts behind a sheet's rim that the leg leaves square to it (a leaf ajar 3
  // degrees, its rim 5 cm from the jamb: the leaf and the jamb read as a gap's two sides). A
  // gap shallower than that, at q, is the rays across's below.
  const glm::vec3 from = q + (std::min(kChannelGapMax, 0.5f * reach) / length) * (end - q);
  if (threadsGap(tracer, along, from, far, true)) return true;
  for (float at : {0.003f, 0.01f, 0.03f})
    if (at < reach && narrowAt(tracer, along, q, far, at / reach)) return true;
  return false;
}

/// True when the leg from a (on edge e) to b (on edge f) passes through a gap (gapBeside, away
/// from both edges' solids where they lie on one side, else either; or both sides closed
/// across it at a quarter, half or three quarters of its length).
bool innerLegInGap(const Tracer& tracer, const DiffractionEdge& e, const DiffractionEdge& f,
                   const glm::vec3& along, const glm::vec3& a, const glm::vec3& b) {
  const float se = solidSide(e, along, a, b), sf = solidSide(f, along, a, b);
  if (gapBeside(tracer, along, a, b, se == sf ? se : 0.f)) return true;
  for (float t : {0.25f, 0.5f, 0.75f})
    if (narrowAt(tracer, along, a, b, t)) return true;
  return false;
}

/// True when the leg from a (on edge e) to b (on edge f) runs along a face that joins the two
/// edges (a reveal from a wall's front corner to its back one) and the face's air side is closed
/// within kChannelGapMax at a quarter, half or three quarters of the leg: a leaf beside the
/// reveal as thick as the wall, whose parallel segments (threadsGap) lie inside the leaf on one
/// side and inside the wall on the other, and whose middle points lie on the reveal itself.
/// The air side is the face's side away from e's other face (e's solid wedge is under pi).
bool faceLegInGap(const Tracer& tracer, const DiffractionEdge& e, const DiffractionEdge& f,
                  const glm::vec3& a, const glm::vec3& b) {
  if (!joinedByFace(e, f)) return false;
  const glm::vec3 u = glm::normalize(b - a);
  const glm::vec3 face1 = std::cos(e.open) * e.face0 + std::sin(e.open) * e.normal0;
  const glm::vec3 other = glm::dot(e.face0, u) > glm::dot(face1, u) ? face1 : e.face0;
  const glm::vec3 solid = other - glm::dot(other, u) * u;
  if (!(glm::length(solid) > 1e-3f)) return false;
  const glm::vec3 air = -glm::normalize(solid);
  for (float t : {0.25f, 0.5f, 0.75f}) {
    const glm::vec3 at = a + t * (b - a);
    if (tracer.occluded(TraceRay{at, air, surfaceOffset(at), kChannelGapMax})) return true;
  }
  return false;
}

/// True when the leg from a to b between two edges runs in the air: free, or free 2 mm to
/// either side (square to it and to the edges, direction `along`). A hinge jamb's leg to its
/// leaf's free rim lies in the leaf's plane (the hinge axis on the jamb's corner), where a ray
/// meets the sheet it grazes.
bool innerLegFree(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a,
                  const glm::vec3& b) {
  constexpr float kGraze = 0.002f;  // m
  if (segmentFree(tracer, a, b)) return true;
  const glm::vec3 n = glm::normalize(glm::cross(b - a, along));
  return segmentFree(tracer, a + kGraze * n, b + kGraze * n) ||
         segmentFree(tracer, a - kGraze * n, b - kGraze * n);
}

/// The side (+1 along normal0, -1 against it) of sheet rim e's plane that a leg in that plane
/// runs along to wrap the rim toward `beyond` (the point the path goes on to past it): the
/// other side; 0 when e is no sheet's rim or the leg (unit u) leaves its plane.
float sheetSide(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& u,
                const glm::vec3& beyond) {
  constexpr float kInPlane = 1e-3f;  // |sin| of the leg's angle to the plane
  if (double(e.open) < 2.0 * kPi - kWrapTolerance || std::abs(glm::dot(u, e.normal0)) > kInPlane)
    return 0.f;
  return glm::dot(beyond - q, e.normal0) > 0.f ? -1.f : 1.f;
}

/// True when the leg from p[i] to p[i + 1] (the chain's points: source, Q..., L) lies in the
/// plane of a sheet whose rim is one of its ends, and the side it must run along to wrap that
/// rim (sheetSide) is closed within kChannelGapMax at a quarter, half or three quarters of it,
/// or the two ends ask for opposite sides of one plane. A sheet leaf slid 2 cm in front of its
/// wall: from its far rim along its back to its near rim is the gap behind it, not a way round.
bool sheetLegInGap(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                   const EdgeChain& c, const std::array<glm::vec3, kChainEdges + 2>& p,
                   size_t i) {
  const glm::vec3 u = glm::normalize(p[i + 1] - p[i]);
  const DiffractionEdge &e = edges[c.edge[i - 1]], &f = edges[c.edge[i]];
  const float first = sheetSide(e, p[i], -u, p[i - 1]);
  const float second = sheetSide(f, p[i + 1], u, p[i + 2]);
  if (first * second * glm::dot(e.normal0, f.normal0) < 0.f) return true;
  for (const auto& [side, n] : {std::pair{first, e.normal0}, std::pair{second, f.normal0}}) {
    if (side == 0.f) continue;
    for (float t : {0.25f, 0.5f, 0.75f}) {
      const glm::vec3 at = p[i] + t * (p[i + 1] - p[i]);
      if (tracer.occluded(TraceRay{at, side * n, surfaceOffset(at), kChannelGapMax})) return true;
    }
  }
  return false;
}

/// The straight line from a to b, past a chain's point: open air, blocked, or threading a gap
/// at most kChannelGapMax wide (free, but threadsGap on one side): a leaf opened 70-90 degrees
/// leaves a gap of a centimetre at its hinge, which the hinge jamb's own path passes as a slit;
/// the chain round the leaf's free rim is the other way round the leaf. An end that is a solid
/// corner's point (`solidA`, `solidB`) is left out of the test for kChannelGapMax, where a
/// parallel segment would start inside the corner's own solid.
enum class Shortcut { kOpen, kBlocked, kThreaded };

Shortcut shortcut(const Tracer& tracer, const glm::vec3& along, const glm::vec3& a,
                  const glm::vec3& b, bool solidA, bool solidB, const DiffractionEdge& past) {
  if (!segmentFree(tracer, a, b)) return Shortcut::kBlocked;
  const float length = glm::distance(a, b);
  if (!(length > 3.f * kChannelGapMax)) return Shortcut::kOpen;
  const glm::vec3 trim = (kChannelGapMax / length) * (b - a);
  const glm::vec3 from = solidA ? a + trim : a, to = solidB ? b - trim : b;
  return gapBeside(tracer, along, from, to, solidSide(past, along, from, to)) ? Shortcut::kThreaded
                                                                              : Shortcut::kOpen;
}

/// Whether the chain's point i (1..n in chainPoints' numbering; 0 and n + 1 are the source
/// and L) lies on a solid corner's edge (a wedge narrower than a sheet's).
bool solidCorner(const std::vector<DiffractionEdge>& edges, const EdgeChain& c, size_t i) {
  return i >= 1 && i <= c.n && double(edges[c.edge[i - 1]].open) < 2.0 * kPi - kWrapTolerance;
}

/// The chain's rays, cheapest refusals first: its outer legs free, its legs in open air but for
/// at most one through a gap (`gapLeg`, EdgeChain's numbering; 0: none), and the shortcut past
/// every Q closed (`threaded`: one only by a gap it threads).
bool chainStands(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                 const EdgeChain& c, const std::array<glm::vec3, kChainEdges + 2>& p,
                 bool& threaded, size_t& gapLeg) {
  const size_t last = c.n + 1;
  if (!segmentFree(tracer, p[last - 1], p[last]) || !segmentFree(tracer, p[0], p[1])) return false;
  const glm::vec3& along = edges[c.edge[0]].direction;
  if (outerLegInGap(tracer, along, p[1], p[0]) ||
      outerLegInGap(tracer, along, p[last - 1], p[last]))
    return false;
  gapLeg = 0;
  for (size_t i = 1; i + 1 < last; ++i) {
    if (!innerLegFree(tracer, along, p[i], p[i + 1]) || sheetLegInGap(tracer, edges, c, p, i) ||
        faceLegInGap(tracer, edges[c.edge[i - 1]], edges[c.edge[i]], p[i], p[i + 1]))
      return false;
    if (!innerLegInGap(tracer, edges[c.edge[i - 1]], edges[c.edge[i]], along, p[i], p[i + 1]))
      continue;
    if (gapLeg != 0) return false;
    gapLeg = i;
  }
  threaded = false;
  for (size_t i = 1; i < last; ++i) {
    const Shortcut past = shortcut(tracer, along, p[i - 1], p[i + 1], solidCorner(edges, c, i - 1),
                                   solidCorner(edges, c, i + 1), edges[c.edge[i - 1]]);
    if (past == Shortcut::kOpen) return false;
    threaded = threaded || past == Shortcut::kThreaded;
  }
  return true;
}

/// True when edge e at q faces a surface within kChannelGapMax past it, along either face's
/// continuation beyond the edge: a moving object's edge closing a gap against the static mesh
/// (a leaf shut in its frame), whose slit the frame's own edges carry (engine/gap_probe.h).
/// A ray along the continuation finds a solid's face; short rays across the continuation's
/// plane, 3 mm to 3 cm out, find a sheet in that plane (a jamb written as one face, which a
/// ray in its own plane does not meet).
bool rimInGap(const Tracer& tracer, const DiffractionEdge& e, const glm::vec3& q) {
  constexpr float kAcross = 0.002f;  // m, either side of the continuation's plane
  const glm::vec3 face1 = std::cos(e.open) * e.face0 + std::sin(e.open) * e.normal0;
  for (const glm::vec3& beyond : {-e.face0, -face1}) {
    if (tracer.occluded(TraceRay{q, beyond, kLegEpsilon, kChannelGapMax})) return true;
    const glm::vec3 n = glm::normalize(glm::cross(e.direction, beyond));
    for (float t : {0.003f, 0.01f, 0.02f, kChannelGapMax}) {
      const glm::vec3 at = q + t * beyond + kAcross * n;
      if (tracer.occluded(TraceRay{at, -n, 0.f, 2.f * kAcross})) return true;
    }
  }
  return false;
}

/// A depth-first search for chains: the edges so far (ids, n of them), each one's point level
/// with the middle of the run along the edges (`mid`: the wedges' angles do not depend on how
/// far along parallel edges the point lies).
struct ChainSearch {
  const Tracer& tracer;
  const std::vector<DiffractionEdge>& edges;
  const std::vector<std::vector<uint32_t>>& near;
  glm::vec3 source, L, d;
  float mid;
  std::vector<EdgeChain> found;
  size_t minEdges;       // the fewest edges a chain takes (1: a moving object's)
  uint32_t objectFrom;   // edges from this index on are a moving object's
  ChainBudget& budget;
  float reach = 0.f;  // m: how far off its edge a Q may fall (layChain)

  glm::vec3 at(uint32_t i) const { return pointAlong(edges[i], d, mid); }

  /// With objectFrom inside the edges, whether ids[0..n) hold edges of both kinds (a chain of
  /// one kind is another pass's); else true.
  bool mixes(const std::array<uint32_t, kChainEdges>& ids, size_t n) const {
    if (objectFrom == 0 || objectFrom >= edges.size()) return true;
    const auto end = ids.begin() + long(n);
    return std::any_of(ids.begin(), end, [&](uint32_t e) { return e >= objectFrom; }) &&
           std::any_of(ids.begin(), end, [&](uint32_t e) { return e < objectFrom; });
  }

  /// Tries the chain ids[0..n) ended at L, then each neighbour of its last edge after it.
  void extend(std::array<uint32_t, kChainEdges>& ids, size_t n) {
    const glm::vec3 before = n >= 2 ? at(ids[n - 2]) : source;
    const uint32_t last = ids[n - 1];
    if (n >= minEdges && wrapsRound(edges[last], at(last), before, L)) keep(ids, n);
    for (uint32_t j : near[last]) {
      if (std::find(ids.begin(), ids.begin() + long(n), j) != ids.begin() + long(n)) continue;
      if (std::abs(glm::dot(edges[j].direction, d)) < kParallelEdges ||
          !wrapsRound(edges[last], at(last), before, at(j)))
        continue;
      if (n == kChainEdges) {  // it would go on round more edges than a chain holds: counted
        ++budget.leftOut;
        return;
      }
      ids[n] = j;
      extend(ids, n + 1);
    }
  }

  /// Whether the chain over ids[0, n) is laid already (a hull's way the search meets again).
  bool laid(const std::array<uint32_t, kChainEdges>& ids, size_t n) const {
    return std::any_of(found.begin(), found.end(), [&](const EdgeChain& c) {
      return c.n == n && std::equal(ids.begin(), ids.begin() + long(n), c.edge.begin());
    });
  }

  /// Each way round the hull of the parallel edges among `from` (engine/hull_ways.h); one round
  /// more edges than a chain holds is counted.
  void hullWays(const std::vector<uint32_t>& from) {
    reach = kChannelGapMax;  // a hull's corner may be a dashed edge (a row of slats' tops)
    for (const std::vector<uint32_t>& way : dpc::hullWays(edges, from, source, L)) {
      if (way.size() > kChainEdges) {
        ++budget.leftOut;
        continue;
      }
      std::array<uint32_t, kChainEdges> ids{};
      std::copy(way.begin(), way.end(), ids.begin());
      const size_t before = found.size();
      if (way.size() >= minEdges) keep(ids, way.size());
      if (found.size() > before) found.back().hull = true;
    }
    reach = 0.f;
  }

  void keep(const std::array<uint32_t, kChainEdges>& ids, size_t n) {
    if (!mixes(ids, n) || laid(ids, n)) return;
    EdgeChain c;
    if (!layChain(edges, ids, n, source, L, c, reach)) return;
    const auto p = chainPoints(c, source, L);
    if (!wrapsAll(edges, c, p)) return;
    if (budget.trials == kChainTrials) {
      ++budget.leftOut;
      return;
    }
    ++budget.trials;
    bool threaded = false;
    if (!chainStands(tracer, edges, c, p, threaded, c.gapLeg)) return;
    if (c.gapLeg != 0) c.gapEnds = {edges[c.edge[c.gapLeg - 1]], edges[c.edge[c.gapLeg]]};
    // A moving object's edges (their gaps are not probed), and every edge of a chain whose
    // shortcut is closed only by a gap it threads (a leaf shut in its frame: round its face
    // from one gap to the other is the slits' way).
    for (size_t i = 0; i < n; ++i)
      if ((threaded || c.edge[i] >= objectFrom) && rimInGap(tracer, edges[c.edge[i]], c.q[i]))
        return;
    found.push_back(c);
  }
};

/// The distance (m) from the segment [p0, p1] to an axis-aligned box [lo, hi], at least:
/// from the box's centre less its half diagonal.
float boxGap(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 centre = 0.5f * (lo + hi);
  return segmentGap(p0, p1, centre, centre) - 0.5f * glm::distance(lo, hi);
}

/// The kChainSeeds nearest of `found` (distance, edge), each once; `leftOut` is increased by
/// the rest; `all` (if given) receives every one, nearest first.
std::vector<uint32_t> nearestSeeds(std::vector<std::pair<float, uint32_t>>& found,
                                   uint32_t& leftOut, std::vector<uint32_t>* all) {
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  if (all) {
    all->clear();
    for (const auto& [d, i] : found) all->push_back(i);
  }
  if (found.size() > kChainSeeds) {
    leftOut += uint32_t(found.size() - kChainSeeds);
    found.resize(kChainSeeds);
  }
  std::vector<uint32_t> out;
  for (const auto& [d, i] : found) out.push_back(i);
  return out;
}

}  // namespace

float segmentGap(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& q0,
                 const glm::vec3& q1) {
  constexpr float kPoint = 1e-12f;  // m^2: a segment this short is a point
  const glm::vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const float a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
  if (a <= kPoint && e <= kPoint) return glm::distance(p0, q0);
  if (a <= kPoint) return glm::distance(p0, q0 + std::clamp(f / e, 0.f, 1.f) * d2);
  const float c = glm::dot(d1, r);
  if (e <= kPoint) return glm::distance(p0 + std::clamp(-c / a, 0.f, 1.f) * d1, q0);
  const float b = glm::dot(d1, d2), denom = a * e - b * b;
  float s = denom > 1e-12f * a * e ? std::clamp((b * f - c * e) / denom, 0.f, 1.f) : 0.f;
  float t = (b * s + f) / e;
  if (t < 0.f || t > 1.f) {
    t = std::clamp(t, 0.f, 1.f);
    s = std::clamp((t * b - c) / a, 0.f, 1.f);
  }
  return glm::distance(p0 + s * d1, q0 + t * d2);
}

std::vector<uint32_t> chainSeeds(const std::vector<uint32_t>& crossed, const SurfaceBodies& bodies,
                                 const std::vector<DiffractionEdge>& edges, const glm::vec3& source,
                                 const glm::vec3& L, uint32_t& leftOut,
                                 std::vector<uint32_t>* all) {
  std::vector<uint32_t> seen;  // bodies
  std::vector<std::pair<float, uint32_t>> found;
  for (uint32_t s : crossed) {
    if (s >= bodies.body.size() || bodies.body[s] >= bodies.members.size()) continue;
    const uint32_t b = bodies.body[s];
    if (std::find(seen.begin(), seen.end(), b) != seen.end()) continue;
    seen.push_back(b);
    for (uint32_t m : bodies.members[b]) {
      if (boxGap(source, L, bodies.box[m].first, bodies.box[m].second) > kChainSearch) continue;
      for (uint32_t i : bodies.edges[m]) {
        const float d = segmentGap(source, L, edges[i].a, edges[i].b);
        if (d <= kChainSearch) found.push_back({d, i});
      }
    }
  }
  return nearestSeeds(found, leftOut, all);
}

std::vector<uint32_t> edgesNearLine(const std::vector<DiffractionEdge>& edges,
                                    const glm::vec3& source, const glm::vec3& L, uint32_t& leftOut,
                                    std::vector<uint32_t>* all) {
  std::vector<std::pair<float, uint32_t>> found;
  for (uint32_t i = 0; i < uint32_t(edges.size()); ++i) {
    const float d = segmentGap(source, L, edges[i].a, edges[i].b);
    if (d <= kChainSearch) found.push_back({d, i});
  }
  return nearestSeeds(found, leftOut, all);
}

std::vector<std::vector<uint32_t>> chainNeighbours(const std::vector<DiffractionEdge>& edges) {
  std::vector<std::vector<uint32_t>> out(edges.size());
  if (edges.empty()) return out;
  EdgeGrid grid(edges, kChainReach);
  for (uint32_t i = 0; i < uint32_t(edges.size()); ++i)
    out[i] = parallelNeighbours(edges, i, i, kChainReach, kChainNeighbours, grid.near(edges[i]));
  return out;
}

std::vector<EdgeChain> edgeChains(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                                  const std::vector<std::vector<uint32_t>>& near,
                                  const std::vector<uint32_t>& seeds, const glm::vec3& source,
                                  const glm::vec3& L, ChainBudget& budget, size_t minEdges,
                                  uint32_t objectFrom, const std::vector<uint32_t>* hullFrom) {
  // The first edge: a seed or a seed's neighbour (a door stop beside the wall's reveal).
  std::vector<uint32_t> firsts = seeds;
  for (uint32_t s : seeds) firsts.insert(firsts.end(), near[s].begin(), near[s].end());
  std::sort(firsts.begin(), firsts.end());
  firsts.erase(std::unique(firsts.begin(), firsts.end()), firsts.end());
  ChainSearch search{tracer, edges,    near,       source, L,     glm::vec3(0.f),
                     0.f,    {},       minEdges,   objectFrom, budget};
  // The ways round the hulls first: a budget spent edge by edge round a row of many posts
  // would leave out the way round its side.
  search.hullWays(hullFrom ? *hullFrom : seeds);
  for (uint32_t f : firsts) {
    search.d = edges[f].direction;
    search.mid = 0.5f * glm::dot(source + L, search.d);
    std::array<uint32_t, kChainEdges> ids{f, 0, 0, 0};
    search.extend(ids, 1);
  }
  return std::move(search.found);
}

void markGraze(const std::vector<DiffractionEdge>& edges,
               const std::vector<std::vector<uint32_t>>& near, uint32_t e, const glm::vec3& source,
               const glm::vec3& L, EdgePath& p) {
  p.grazeExcess = -1.f;
  for (uint32_t j : near[e])
    for (int order = 0; order < 2; ++order) {
      const std::array<uint32_t, kChainEdges> ids =
          order == 0 ? std::array<uint32_t, kChainEdges>{e, j, 0, 0}
                     : std::array<uint32_t, kChainEdges>{j, e, 0, 0};
      EdgeChain c;
      if (!layChain(edges, ids, 2, source, L, c, 0.f)) continue;
      const auto at = chainPoints(c, source, L);
      const size_t k = order == 0 ? 1 : 0;  // j's place in the chain
      if (!clearsOnLitSide(edges[j], c.q[k], at[k], at[k + 2])) continue;
      const float excess = std::max(0.f, c.length - p.legs);
      if (p.grazeExcess >= 0.f && excess >= p.grazeExcess) continue;
      p.grazeExcess = excess;
      p.grazeSpan = glm::distance(c.q[0], c.q[1]);
    }
}

}  // namespace dpc
