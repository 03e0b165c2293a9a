// Paths round two to four edges in series (one to four of a moving object's, engine/
// object_edges.h): a pillar or a crate between the source and the listener, a door frame's stop
// and then the reveal's corner, a thick wall's jamb passed from one side to the other. A
// first-order edge path (engine/edge_path.h) over either edge has a leg through the other's
// body: with the line of sight blocked, these paths are all the direct sound there is.
//
// The path: source -> Q1 -> ... -> Qn -> listener (n = 2 to kChainEdges) over parallel edges
// (kParallelEdges), each Q on its edge, of least length (Fermat: unfolded about the edges it is
// a straight line, so the Q divide the path's run along the edges as its length across them
// divides). It stands when every leg is free, every leg between two edges runs in open air (not
// through a gap at most kChannelGapMax wide: a door's gaps are its slits' and channels'; one
// leg may, where no path carries that gap's slit: EdgeChain::gapLeg), and
// every Q is a corner the path wraps round: the straight line from the point before it to the
// point after it is blocked or threads a gap of at most kChannelGapMax (then no edge of the
// chain may face a surface that close past it), and both lie in its air wedge, on either side
// of its shadow boundary. Chains are laid over the edges of the bodies the line of sight crosses
// that lie within kChainSearch of it, and over the edges near those (kChainReach, at load),
// and round the hull of those edges (engine/hull_ways.h: a row of posts in line). A leg whose
// end edges' solids lie on one side of it is tested for a gap on the other side only (along a
// row's side it passes the slots between the posts).
//
// Its level is a barrier's attenuation over the free field at the direct distance, ISO
// 9613-2:1996 eq. (14): Dz = 10 lg(3 + (C2 / lambda) C3 z), z the path's length less the direct
// distance, C2 = 40 (reflections are the tracer's, not part of the screen term), C3 =
// (1 + (5 lambda / e)^2) / (1/3 + (5 lambda / e)^2), e the distance from the first Q to the
// last (engine/barrier.h); meteorological correction 1 (indoors), no upper limit. Averaged in
// energy over the frequencies of each band (diffractionFrequencyHz). The attenuation carries
// no phase of its own: the chains add in pressure among themselves with their lengths' phases
// (engine/chain_sum.h chainsGain), and in energy to the coherent sum of the direct sound and the
// first-order paths.
//
// Internal to the engine (engine/diffraction.cpp). Load: chainNeighbours. Per query: any thread
// (reentrant, tracer queries only); allocates small vectors; no errors.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"
#include "engine/diffraction.h"
#include "engine/edge_path.h"
#include "engine/tracer.h"

namespace dpc {

/// m: how far apart two edges of one chain may lie (a pillar's or a crate's width, a wall's
/// thickness, a stop beside its reveal), and how many of the nearest each edge keeps.
inline constexpr float kChainReach = 1.f;
inline constexpr size_t kChainNeighbours = 8;
/// The most edges in one chain; a chain that would wrap round more is counted as left out (the
/// search round a column of three posts in line meets ways round six).
inline constexpr size_t kChainEdges = 4;
/// m: how far from the line of sight the edges a chain is laid from lie, and the most of them
/// per query (the nearest); and the most chains whose rays are cast (the first met) per query
/// over the static mesh and over each moving object near the line of sight (ChainBudget).
/// What the caps leave out is counted (DirectSound::chainsLeftOut). A pillar takes 2 chains, a
/// door frame's stop a few, slatted shelving or a grid of posts a few dozen.
inline constexpr float kChainSearch = 2.f;
inline constexpr size_t kChainSeeds = 24;
inline constexpr size_t kChainTrials = 64;

/// One path round n edges in series: their indices and points (m), its length (m).
struct EdgeChain {
  std::array<uint32_t, kChainEdges> edge{};
  std::array<glm::vec3, kChainEdges> q{};
  size_t n = 0;
  float length = 0.f;
  /// The moving object whose edges these are (engine/object_edges.h), scene order; -1: the
  /// static mesh's.
  int object = -1;
  /// Its first and last edges as laid (a mixed chain's indices are into its query's own list:
  /// engine/chain_sum.cpp), for the openings at its ends (engine/openings.h); an opening's path
  /// points at them (EdgePath::edge), so the query's chains stay put once openings are added.
  std::array<DiffractionEdge, 2> ends{};
  /// The index in the query's paths of the path that carries the opening beside its ends
  /// (engine/openings.h addChainOpenings); -1: none.
  int32_t opening = -1;
  /// The leg between two of its edges that threads a gap no wider than kChannelGapMax on a
  /// side (a leaf ajar toward the source: from its rim past the jamb's corner into the
  /// doorway): k, the leg from q[k - 1] to q[k], and those two edges as laid; 0: none. It
  /// stands only between a small body and a large one, as the other side of that opening's
  /// slit, found beside the small body's end of the leg (engine/openings.h addChainOpenings).
  size_t gapLeg = 0;
  std::array<DiffractionEdge, 2> gapEnds{};
  /// A way round the hull of a group of bodies (engine/hull_ways.h), not one found edge by edge.
  bool hull = false;
};

/// The chains whose rays were cast (at most kChainTrials per query over the static mesh, and
/// as many over each moving object near the line of sight) and those left out past that.
struct ChainBudget {
  size_t trials = 0;
  uint32_t leftOut = 0;
};

/// The distance (m) between the segments [p0, p1] and [q0, q1] (closest points by clamped
/// parameters: C. Ericson, Real-Time Collision Detection, 2005, sec. 5.1.9). Any thread.
float segmentGap(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& q0,
                 const glm::vec3& q1);

/// Per edge, the edges parallel to it (kParallelEdges) whose lines pass within kChainReach of
/// its line beside it, overlapping it along its length: the kChainNeighbours nearest, nearest
/// first. Load time; allocates; the edges binned in a grid (engine/edge_grid.h).
std::vector<std::vector<uint32_t>> chainNeighbours(const std::vector<DiffractionEdge>& edges);

/// The edges a query's chains are laid from: those of the bodies (SurfaceBodies) of the flat
/// surfaces the line of sight crosses (`crossed`, sorted; kMovingObjects and unknown ones
/// skipped) within kChainSearch of the segment from source to L, the kChainSeeds nearest;
/// `leftOut` receives how many more there were; `all` (if given) every one of them, nearest
/// first (edgeChains looks for the hulls' ways among them all).
std::vector<uint32_t> chainSeeds(const std::vector<uint32_t>& crossed, const SurfaceBodies& bodies,
                                 const std::vector<DiffractionEdge>& edges, const glm::vec3& source,
                                 const glm::vec3& L, uint32_t& leftOut,
                                 std::vector<uint32_t>* all = nullptr);

/// The edges within kChainSearch of the segment from source to L, the kChainSeeds nearest;
/// `leftOut` is increased by how many more there were (a moving object's edges); `all` as for
/// chainSeeds.
std::vector<uint32_t> edgesNearLine(const std::vector<DiffractionEdge>& edges,
                                    const glm::vec3& source, const glm::vec3& L, uint32_t& leftOut,
                                    std::vector<uint32_t>* all = nullptr);

/// The chains from source to L (m) laid from `seeds` (indices into edges: the edges of the
/// bodies the line of sight crosses) or their neighbours `near` (chainNeighbours), each once,
/// over neighbours. Rays: up to 49 per chain whose geometry stands (its legs, shortcuts and gap
/// tests), while `budget` allows (kChainTrials a query; what it leaves out is counted there).
/// minEdges: the fewest edges a chain takes (2: one is a first-order path, UTD's; 1 for a
/// moving object's edges, which have no first-order paths of their own). objectFrom: the edges
/// from this index on are a moving object's: none of them may face a surface within
/// kChannelGapMax past it (a leaf shut in its frame is the frame's slits'); strictly inside
/// the edges, only the chains holding edges of both kinds are laid. hullFrom: the edges whose
/// hulls' ways (engine/hull_ways.h) are laid first, before the budget goes edge by edge (the
/// seeds if null): the way round a row of twenty posts seen end on wraps its first and last
/// posts' corners, which the nearest seeds leave out.
std::vector<EdgeChain> edgeChains(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                                  const std::vector<std::vector<uint32_t>>& near,
                                  const std::vector<uint32_t>& seeds, const glm::vec3& source,
                                  const glm::vec3& L, ChainBudget& budget, size_t minEdges = 2,
                                  uint32_t objectFrom = UINT32_MAX,
                                  const std::vector<uint32_t>* hullFrom = nullptr);

/// Sets p.grazeExcess to the least path-length excess (m) of a detour from first-order path p
/// (over edges[e], its legs free) round a neighbour of e (`near`, chainNeighbours) that one of
/// its legs passes on the lit side (the detour does not wrap the neighbour, whose wider wedge
/// holds both ends of the leg), laid as a chain at its point of least length, and p.grazeSpan
/// to the distance between the two edges' points; -1 when there is none. Geometry only.
void markGraze(const std::vector<DiffractionEdge>& edges,
               const std::vector<std::vector<uint32_t>>& near, uint32_t e, const glm::vec3& source,
               const glm::vec3& L, EdgePath& p);

}  // namespace dpc
