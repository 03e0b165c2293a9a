#include "engine/diffraction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <limits>
#include <numbers>
#include <utility>

#include "engine/chain_sum.h"
#include "engine/channel_path.h"
#include "engine/channel_turn.h"
#include "engine/coherent_sum.h"
#include "engine/diffraction_edges.h"
#include "engine/edge_chain.h"
#include "engine/edge_path.h"
#include "engine/finite_edge.h"
#include "engine/gap_probe.h"
#include "engine/object_edges.h"
#include "engine/openings.h"
#include "engine/path_slits.h"
#include "engine/slit.h"
#include "engine/small_bodies.h"
#include "engine/surface_bound.h"
#include "engine/threaded_legs.h"
#include "engine/turned_legs.h"

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

/// A free edge on the far side of a slit another edge found (a leaf's free edge across the
/// opening from the jamb whose probe met the leaf) bounds that slit: its UTD field is the
/// slit's other edge, which the slit's field replaces in the proportion s (engine/slit.h).
/// Left free, it added that edge's field beside the slit's: a leaf ajar 20 degrees, seen from
/// beside the doorway, read 16 dB below the open doorway at 63 Hz. Partner: across the slit
/// (acrossSlit, engine/edge_path.h).
void markSlitPartners(std::vector<EdgePath>& paths, const SurfaceBodies& bodies) {
  for (EdgePath& p : paths) {
    if (p.gapWidth != 0.f || p.atEnd) continue;
    for (const EdgePath& o : paths) {
      if (!(o.gapWidth > 0.f) || !o.slitOwner || &o == &p || !acrossSlit(o, p, &bodies.body))
        continue;
      takeSlit(p, o);
      break;
    }
  }
}

/// The direct sound's band intensity with nothing in its way (1/m^2): spreading over the
/// direct distance, the air's attenuation and the source's weight toward the listener.
Bands unobstructedIntensity(const glm::vec3& source, const glm::vec3& L, const DirectSound& d,
                            const Bands& airPerMetre, const Directivity& directivity,
                            const glm::vec3& forward) {
  Bands i = exp(airPerMetre * -d.distance) * (1.f / (4.f * float(kPi) * d.distance * d.distance));
  const glm::vec3 v = L - source;
  const float length = glm::length(v);
  if (!directivity.omni() && length > 0.f)
    i *= directivityWeight(directivity, glm::dot(forward, v / length));
  return i;
}

/// The path over every edge, into the result when both its legs are free, into q.hidden when
/// one is blocked; the corner paths (cornerPath: a thin sheet's edge whose Q lies past its
/// run's end) with free legs into `corners`, kept apart from the gap probes.
std::vector<EdgePath> edgePaths(const std::vector<DiffractionEdge>& edges, bool lineOfSight,
                                BoundQuery& q, std::vector<EdgePath>& corners) {
  std::vector<EdgePath> paths;
  for (const DiffractionEdge& e : edges) {
    EdgePath p;
    const bool onEdge = edgePath(e, q.source, q.L, lineOfSight, p);
    if (!onEdge) {  // a corner's wave (a fresh path: edgePath may have set some fields)
      if (!e.freeEnds) continue;
      p = EdgePath{};
      if (!cornerPath(e, q.source, q.L, lineOfSight, p)) continue;
    }
    // Before the legs' test: a hidden path comes back when what hides it is taken away.
    findAbsentReflections(q.tracer, q.source, q.L, lineOfSight, p);
    if (!legsFree(q.tracer, q.source, q.L, p))
      q.hidden.push_back({p, {}, false});
    else
      (onEdge ? paths : corners).push_back(p);
  }
  return paths;
}

/// m: how far from a slit already found an edge's end may lie for addEndSlits (a door's size).
constexpr float kEndSlitReach = 3.f;

/// The surfaces on either side of the gaps among the paths and the closed ones (a leaf shut
/// tight at its sides may leave an undercut), sorted, each once.
std::vector<uint32_t> slitSurfaces(const std::vector<EdgePath>& paths,
                                   const std::vector<EdgePath>& closed) {
  std::vector<uint32_t> out;
  for (const EdgePath& p : paths)
    if (p.gapWidth > 0.f)
      out.insert(out.end(), {p.edge->surfaces[0], p.edge->surfaces[1], p.gapCloser});
  for (const EdgePath& p : closed)
    out.insert(out.end(), {p.edge->surfaces[0], p.edge->surfaces[1], p.gapCloser});
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Adds the slits whose edges have no point of least length on them: seen from off a door's
/// axis, its top gap's and undercut's edges end before the stationary point, yet the slit, a
/// line source along its extent, still passes sound (its Fresnel integral between its ends,
/// engine/slit.h). Looked for on the surfaces that bound a gap already found, open or closed
/// (the leaf and its frame, by their side gaps), over edges within kEndSlitReach of one, and on
/// the surfaces that block the line of sight (a leaf tight in its frame but for an undercut),
/// with Q at the edge's nearer end (edgePath's atEnd: no UTD field); kept when both legs are
/// free and a gap is there.
void addEndSlits(const std::vector<DiffractionEdge>& edges, bool lineOfSight, BoundQuery& q,
                 std::vector<EdgePath>& paths) {
  const std::vector<uint32_t> slitted = slitSurfaces(paths, q.closed);
  const std::vector<uint32_t>& blocking = q.crossed;
  if (slitted.empty() && blocking.empty()) return;
  auto on = [](const std::vector<uint32_t>& set, const DiffractionEdge& e) {
    return std::binary_search(set.begin(), set.end(), e.surfaces[0]) ||
           std::binary_search(set.begin(), set.end(), e.surfaces[1]);
  };
  auto nearSlit = [&](const glm::vec3& point) {
    auto near = [&](const EdgePath& p) {
      return glm::distance(p.gapWidth > 0.f ? p.slitCentre : p.q, point) < kEndSlitReach;
    };
    return std::any_of(paths.begin(), paths.end(),
                       [&](const EdgePath& p) { return p.gapWidth > 0.f && near(p); }) ||
           std::any_of(q.closed.begin(), q.closed.end(), near);
  };
  std::vector<EdgePath> ends, closed;
  for (const DiffractionEdge& e : edges) {
    const bool blocks = on(blocking, e);
    if (!blocks && !on(slitted, e)) continue;
    EdgePath p;
    if (!edgePath(e, q.source, q.L, lineOfSight, p, true) || !(blocks || nearSlit(p.q)) ||
        !legsFree(q.tracer, q.source, q.L, p))
      continue;
    ends.push_back(p);
  }
  if (ends.empty()) return;
  findSlits(q.tracer, q.source, q.L, q.surfaces, ends, closed, &q.bodies);
  for (const EdgePath& p : ends)
    if (p.gapWidth > 0.f) paths.push_back(p);
  markSlitOwners(paths, &q.bodies.body);
}

/// Probes the channels' gaps (findSlits) and adds to paths those the probe finds open: up to
/// the face's depth or kChannelGapMax, and wider where the gap's far side stands across the
/// face, a slit of that width and depth (the slit model gives way to the edges by its own k w
/// and aspect, engine/slit.h). Dropped past the face's depth, a box leaf 4 cm deep with a
/// 42-60 mm undercut read the open doorway, 18 dB above the slit model at 63 Hz. A turned
/// channel with no gap across its face takes the opening at its mouth (openChannel) up to the
/// face's depth or kChannelGapMax.
void keepOpenChannels(std::vector<EdgePath>& channels, BoundQuery& q,
                      std::vector<EdgePath>& paths) {
  if (channels.empty()) return;
  std::vector<EdgePath> closed;
  findSlits(q.tracer, q.source, q.L, q.surfaces, channels, closed, &q.bodies);
  for (EdgePath& p : channels) {
    const float widest = std::max(glm::length(p.through), kChannelGapMax);
    const bool turned = p.before + p.lipBefore + p.beyond + p.lipBeyond != glm::vec3(0.f);
    const float t = glm::dot(p.q - p.edge->a, p.edge->direction);
    const bool across = !turned || gapAcross(q.tracer, *p.edge, p.through, t);
    // Past the face's depth only where the gap's far side stands across the face (the slit
    // has depth): a mouth with nothing across it (a leaf filling its doorway, the probe's legs
    // meeting the wall's face before the reveal) reads no gap of its own.
    const bool slit = p.gapWidth <= widest || p.slit.depth > 0.0;
    if ((across && p.gapWidth > 0.f && slit) ||
        (turned && (!across || p.gapWidth == 0.f) && openChannel(p, q, widest, paths)))
      paths.push_back(p);
  }
  markSlitOwners(paths, &q.bodies.body);
}

/// Adds the channels (engine/channel_path.h) along the narrow faces `faces` whose legs are free
/// and whose gap the probe finds open (a closed box leaf's gaps to its frame and the floor;
/// keepOpenChannels).
void addChannels(const std::vector<DiffractionEdge>& edges, const std::vector<NarrowFace>& faces,
                 BoundQuery& q, std::vector<EdgePath>& paths) {
  std::vector<EdgePath> channels;
  for (const NarrowFace& f : faces)
    for (int way = 0; way < 2; ++way) {
      const uint32_t a = way == 0 ? f.a : f.b, b = way == 0 ? f.b : f.a;
      EdgePath p;
      if ((channelPath(edges[a], edges[b], q.source, q.L, p) &&
           legsFree(q.tracer, q.source, q.L, p)) ||
          visibleChannel(q.tracer, edges[a], edges[b], q.source, q.L, p) ||
          turnedChannel(q.tracer, edges, edges[a], edges[b], f.near[size_t(1 - way)],
                        f.near[size_t(way)], q.source, q.L,
                        !largeBody(q.bodies, edges[a].surfaces[0]), p)) {
        // A turned channel's legs start at its mouths as found: its depth is not measured
        // again (moving the mouths would leave the turns' offsets behind).
        const bool turned = p.before + p.lipBefore + p.beyond + p.lipBeyond != glm::vec3(0.f);
        p.measuredDepth = !turned && largeBody(q.bodies, p.edge->surfaces[0]);
        channels.push_back(p);
      }
    }
  keepOpenChannels(channels, q, paths);
}

/// Adds the channels along the moving objects' narrow faces near the line of sight that turn
/// round a door stop in the mesh (engine/object_edges.h objectChannels), as addChannels does.
void addObjectChannels(const std::vector<DiffractionEdge>& edges,
                       const std::vector<ObjectEdges>& objects, BoundQuery& q,
                       std::vector<EdgePath>& paths) {
  std::vector<EdgePath> channels;
  for (const ObjectEdges& o : objects) {
    if (!nearLine(o, q.source, q.L)) continue;
    std::vector<EdgePath> more = objectChannels(q.tracer, edges, o, q.source, q.L);
    channels.insert(channels.end(), more.begin(), more.end());
  }
  keepOpenChannels(channels, q, paths);
}

/// A moving object's edge taken alone (a one-edge chain: objects have no first-order paths)
/// whose gap the probe finds open becomes that slit's edge path: a game door's free rim ajar a
/// few degrees, whose leg hides the latch jamb's from the listener, bounds the latch gap, and
/// as a chain it added a free edge's field (the door read the open doorway at 63 Hz, 6 dB
/// above the same leaf in the static mesh). Its chain goes; a rim with no gap, or with a gap
/// too short along it for the slit model (slitWeight 0: its field would be UTD's alone, and
/// unbounded as a first-order path where the chain's is held), stays a chain, unless an
/// opening the probe misses lies beside it (engine/openings.h: openFreeEdges makes that its
/// slit, as for the same rim in the mesh).
void addObjectRims(const std::vector<ObjectEdges>& objects, BoundQuery& q,
                   std::vector<EdgeChain>& chains, std::vector<EdgePath>& paths) {
  std::vector<EdgePath> rims, closed;
  std::vector<size_t> from;  // per rim, its chain
  for (size_t c = 0; c < chains.size(); ++c) {
    if (chains[c].object < 0 || chains[c].n != 1) continue;
    const DiffractionEdge& e = objects[size_t(chains[c].object)].world[chains[c].edge[0]];
    EdgePath p;
    if (!edgePath(e, q.source, q.L, false, p) || !legsFree(q.tracer, q.source, q.L, p)) continue;
    findAbsentReflections(q.tracer, q.source, q.L, false, p);
    rims.push_back(p);
    from.push_back(c);
  }
  if (rims.empty()) return;
  std::vector<EdgePath> probed = rims;
  findSlits(q.tracer, q.source, q.L, q.surfaces, probed, closed, &q.bodies);
  std::vector<bool> drop(chains.size(), false);
  for (const EdgePath& p : probed) {
    const bool slit = p.gapWidth > 0.f && p.slitAspect >= kSlitMinAspect;
    if (!slit && !hasOpening(p, q, paths)) continue;
    const auto k = size_t(std::find_if(rims.begin(), rims.end(), [&](const EdgePath& r) {
                            return r.edge == p.edge;
                          }) - rims.begin());
    if (k == rims.size()) continue;
    drop[from[k]] = true;
    paths.push_back(p);
  }
  size_t kept = 0;
  for (size_t c = 0; c < chains.size(); ++c)
    if (!drop[c]) chains[kept++] = chains[c];
  chains.resize(kept);
}


/// Each free edge path's grazeExcess and grazeSpan (engine/edge_chain.h markGraze), the line of
/// sight blocked: a pillar's near corner's path whose leg just clears its far corner takes that
/// corner's lit-side transition, and so nears the chain round both corners that takes over
/// where the leg is blocked.
void markGrazes(const std::vector<DiffractionEdge>& edges,
                const std::vector<std::vector<uint32_t>>& near, const BoundQuery& q,
                std::vector<EdgePath>& paths) {
  for (EdgePath& p : paths)
    if (p.gapWidth == 0.f && !p.atEnd && p.through == glm::vec3(0.f) &&
        edgeIndex(edges, p) < edges.size())
      markGraze(edges, near, uint32_t(edgeIndex(edges, p)), q.source, q.L, p);
}

/// With the line of sight blocked: the openings beside small bodies' edges and chains' ends
/// (engine/openings.h),
/// who carries each slit and who is its other side settled again, and the grazes.
void inShadow(const std::vector<DiffractionEdge>& edges,
              const std::vector<std::vector<uint32_t>>& near, const SurfaceBodies& bodies,
              std::vector<EdgeChain>& chains, BoundQuery& q, std::vector<EdgePath>& paths) {
  openFreeEdges(paths, q);
  addChainOpenings(chains, paths, q);
  markSlitOwners(paths, &bodies.body);
  markSlitPartners(paths, bodies);
  markGrazes(edges, near, q, paths);
}

/// Whether slit path p's gap lies between two small static bodies (not largeBody: two slats of
/// a screen, two posts), its edge's and its closer's; a door's gaps, whose jamb is a wall's,
/// are not.
bool betweenSmallBodies(const EdgePath& p, const SurfaceBodies& bodies) {
  return smallBody(bodies, p.edge->surfaces[0]) && smallBody(bodies, p.gapCloser);
}

/// Whether `level` lies below `free` by more than kShortOfFree in some band (1/m^2 each): a
/// line of sight through a slot that already passes the free field needs no second look.
bool shortOf(const Bands& level, const Bands& free) {
  constexpr float kShortOfFree = 0.977f;  // -0.1 dB
  for (int b = 0; b < kNumBands; ++b)
    if (level[b] < kShortOfFree * free[b]) return true;
  return false;
}

/// The shortest of the direct sound (when visible), the edge paths and the slit paths: its
/// length (m) and its arrival direction (unit vector from the listener at q.L); with none (only
/// the thin bodies' floor), the straight line through them.
std::pair<float, glm::vec3> firstArrival(const std::vector<EdgePath>& paths,
                                         const std::vector<EdgeChain>& chains,
                                         const DirectSound& direct, const BoundQuery& q) {
  const glm::vec3& L = q.L;
  float shortest = direct.visible ? direct.distance : 1e30f;
  glm::vec3 arrival = direct.direction;
  for (const EdgePath& p : paths) {
    if (!p.atEnd && p.legs < shortest) {
      shortest = p.legs;
      arrival = p.arrival;
    }
    if (p.gapWidth > 0.f && float(p.slit.r + p.slit.s) < shortest) {
      shortest = float(p.slit.r + p.slit.s);
      arrival = glm::normalize(p.slitCentre - L);
    }
  }
  for (const EdgeChain& c : chains)
    if (c.length < shortest) {
      shortest = c.length;
      arrival = glm::normalize(c.q[c.n - 1] - L);
    }
  if (!(shortest < 1e29f)) {
    shortest = glm::distance(q.source, L);
    arrival = (q.source - L) / std::max(shortest, 1e-6f);
  }
  return {shortest, arrival};
}

/// The band intensity of the direct sound with the edge and slit paths (their coherent sum,
/// held where heldBound says) and the chains round edges in series, plus what the direct sound
/// passes through transmitting surfaces (added in energy); with the line of sight blocked, at
/// most the unobstructed direct sound.
Bands directIntensity(const std::vector<EdgePath>& paths, const std::vector<EdgeChain>& chains,
                      const DirectSound& direct, BoundQuery& q) {
  DirectSound coherent = direct;
  coherent.visible = direct.lineOfSight();
  const EdgePath* throughSlit =
      coherent.visible ? slitOnLineOfSight(paths, q.source, q.L) : nullptr;
  const Bands free =
      unobstructedIntensity(q.source, q.L, direct, q.airPerMetre, q.directivity, q.forward);
  Bands sum = coherentIntensity(paths, coherent, throughSlit, q.speedOfSound, q.airPerMetre,
                                leavingWeights(paths, q.directivity, q.forward));
  sum = min(sum, heldBound(paths, coherent, throughSlit, free, sum, q));
  if (coherent.visible) return max(sum, q.smallFloor);
  sum = max(withChains(paths, chains, coherent, direct, free, sum, q),
            thinBodiesFloor(paths, coherent, free, q));
  return min(sum + (direct.visible ? direct.intensity : Bands(0.f)), free);
}

/// Whether, with no edge path or chain, the line of sight is blocked only by thin bodies that
/// keep a floor (engine/small_bodies.h thinBodiesFloor): a table top seen edge on, the line of
/// sight inside its thickness, has no path round it within the chains' reach.
bool thinBodiesOnly(const DirectSound& direct, BoundQuery& q) {
  if (direct.lineOfSight() || q.crossed.empty()) return false;
  DirectSound blocked = direct;
  blocked.visible = false;
  const Bands free =
      unobstructedIntensity(q.source, q.L, direct, q.airPerMetre, q.directivity, q.forward);
  return thinBodiesFloor({}, blocked, free, q).max() > 0.f;
}

/// The indices in `edges` of the static edges the paths and the chains use, in order (cleared
/// first); a moving object's channels' edges are not among them.
void listUsedEdges(const std::vector<EdgePath>& paths, const std::vector<EdgeChain>& chains,
                   const std::vector<DiffractionEdge>& edges, std::vector<uint32_t>& out) {
  out.clear();
  for (const EdgePath& p : paths)
    if (const size_t i = edgeIndex(edges, p); i < edges.size()) out.push_back(uint32_t(i));
  for (const EdgeChain& c : chains)
    if (c.object < 0) out.insert(out.end(), c.edge.begin(), c.edge.begin() + long(c.n));
}

}  // namespace

double diffractionFrequencyHz(int band, int i) {
  return bandCentreExactHz(band) * std::exp2((i + 0.5) / kDiffractionFrequenciesPerBand - 0.5);
}

EdgeDiffraction::EdgeDiffraction(const Mesh& mesh, const std::vector<ObjectDesc>& objects)
    : surfaces_(flatSurfaces(mesh)),
      bodies_(surfaceBodies(mesh, surfaces_)),
      edges_(candidateEdges(mesh, surfaces_)) {
  bodies_.extent = freeStandingExtents(mesh, surfaces_, bodies_, edges_);
  bodies_.edges = surfaceEdges(bodies_.box.size(), edges_);
  narrow_ = narrowFaces(edges_, bodies_.edges);
  chainNear_ = chainNeighbours(edges_);
  markFreeEnds(bodies_, chainNear_, edges_);
  objects_ = objectEdges(objects);
  // A narrow face of a body too large to be taken away whole (a thick wall's reveal) does not
  // stand free: taken away alone, it opens the body it closes. A small body's narrow faces (a
  // slat's, a box leaf's sides) stay: the body goes whole (engine/surface_bound.h).
  for (const NarrowFace& f : narrow_)
    for (uint32_t s : edges_[f.a].surfaces) {
      if (s != edges_[f.b].surfaces[0] && s != edges_[f.b].surfaces[1]) continue;
      if (s < bodies_.extent.size() && largeBody(bodies_, s))
        bodies_.extent[s] = std::numeric_limits<float>::infinity();
    }
}

void EdgeDiffraction::setObjectPoses(const std::vector<Pose>& poses) {
  for (size_t k = 0; k < objects_.size() && k < poses.size(); ++k)
    placeObjectEdges(objects_[k], poses[k]);
}

size_t EdgeDiffraction::apply(const Tracer& tracer, const glm::vec3& source,
                              const ListenerSphere& listener, float speedOfSound,
                              const Bands& airPerMetre, DirectSound& direct,
                              const Directivity& directivity, const glm::vec3& forward,
                              std::vector<uint32_t>* usedEdges) const {
  // Diffraction needs the free line of sight: a direct path through transmitting surfaces is
  // in the shadow for the edges, and its energy adds to theirs incoherently (the edge paths'
  // legs are unoccluded, the transmitted path crosses a surface: no path is counted twice).
  const bool lineOfSight = direct.lineOfSight();
  const Bands unobstructed = direct.intensity;
  BoundQuery query =
      newQuery(tracer, source, listener.position, speedOfSound, airPerMetre, directivity, forward);
  direct.chainsLeftOut = 0;
  std::vector<EdgePath> paths;
  std::vector<EdgeChain> chains;
  layPaths(lineOfSight, query, paths, chains, direct.chainsLeftOut);
  if (usedEdges) listUsedEdges(paths, chains, edges_, *usedEdges);
  if (paths.empty() && chains.empty() && !thinBodiesOnly(direct, query)) return 0;
  const auto [shortest, arrival] = firstArrival(paths, chains, direct, query);
  direct.intensity = directIntensity(paths, chains, direct, query);
  const EdgePath* slit = lineOfSight ? slitOnLineOfSight(paths, source, query.L) : nullptr;
  if (slit && betweenSmallBodies(*slit, bodies_) && shortOf(direct.intensity, unobstructed))
    direct.intensity =
        max(direct.intensity, slitClosedIntensity(*slit, query, direct, direct.chainsLeftOut));
  direct.visible = true;
  direct.distance = shortest;
  direct.delaySeconds = shortest / speedOfSound;
  direct.direction = arrival;
  return paths.size() + chains.size();
}

BoundQuery EdgeDiffraction::newQuery(const Tracer& tracer, const glm::vec3& source,
                                     const glm::vec3& L, float speedOfSound,
                                     const Bands& airPerMetre, const Directivity& directivity,
                                     const glm::vec3& forward) const {
  BoundQuery q{tracer, source, L,  surfaces_,    bodies_,     edges_,      {},
               {},     {},     {}, speedOfSound, airPerMetre, directivity, forward};
  q.objects = !objects_.empty();
  return q;
}

void EdgeDiffraction::layPaths(bool lineOfSight, BoundQuery& query, std::vector<EdgePath>& paths,
                               std::vector<EdgeChain>& chains, uint32_t& chainsLeftOut) const {
  const Tracer& tracer = query.tracer;
  const glm::vec3 source = query.source, L = query.L;
  std::vector<EdgePath> corners;
  paths = edgePaths(edges_, lineOfSight, query, corners);
  if (query.crossed.empty()) crossLineOfSight(lineOfSight, query);
  if (!lineOfSight) chains = laidChains(query, objects_, chainNear_, chainsLeftOut);
  findSlits(tracer, source, L, surfaces_, paths, query.closed, &bodies_);
  paths.insert(paths.end(), corners.begin(), corners.end());
  if (!lineOfSight) addTurnedLegs(edges_, chainNear_, objects_, query, paths);
  addChannels(edges_, narrow_, query, paths);
  addObjectChannels(edges_, objects_, query, paths);
  addObjectRims(objects_, query, chains, paths);
  dropThreadedPaths(query, paths);
  markSlitOwners(paths, &bodies_.body);
  markSlitPartners(paths, bodies_);
  markReveals(source, L, paths);
  addEndSlits(edges_, lineOfSight, query, paths);
  if (!lineOfSight) inShadow(edges_, chainNear_, bodies_, chains, query, paths);
}

Bands EdgeDiffraction::slitClosedIntensity(const EdgePath& slit, const BoundQuery& open,
                                           const DirectSound& direct, uint32_t& leftOut) const {
  BoundQuery query = newQuery(open.tracer, open.source, open.L, open.speedOfSound, open.airPerMetre,
                              open.directivity, open.forward);
  query.crossed.assign(slit.edge->surfaces.begin(), slit.edge->surfaces.end());
  std::sort(query.crossed.begin(), query.crossed.end());
  query.crossed.erase(std::unique(query.crossed.begin(), query.crossed.end()), query.crossed.end());
  DirectSound closed = direct;
  closed.visible = false;
  closed.intensity = Bands(0.f);
  std::vector<EdgePath> paths;
  std::vector<EdgeChain> chains;
  layPaths(false, query, paths, chains, leftOut);
  if (paths.empty() && chains.empty()) return Bands(0.f);
  return directIntensity(paths, chains, closed, query);
}

}  // namespace dpc
