// Diffracting edges binned by space, to find the edges near an edge at load time without
// comparing every pair (8000 crates, 96,000 edges: seconds scanning every edge per edge).
//
// Internal to the engine. Load time only; allocates; not reentrant (a query marks the edges it
// has listed); no errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <unordered_map>
#include <vector>

#include "engine/diffraction.h"

namespace dpc {

/// Edges binned by the cells (1.3 reach wide) of points sampled along them every reach / 4: an
/// edge whose line passes within `reach` of another's, beside it, has a sample within
/// 1.25 reach of one of the other's, so in one of the 27 cells round it.
class EdgeGrid {
 public:
  /// reach: m, > 0 (a smaller one is taken as 1 mm).
  EdgeGrid(const std::vector<DiffractionEdge>& edges, float reach);

  /// The edges with a sample in a cell next to one of e's samples' (e included if binned),
  /// each once: a superset of the edges within `reach` of e. About (e's length / (reach / 4))
  /// * 27 cell look-ups.
  std::vector<uint32_t> near(const DiffractionEdge& e);

 private:
  template <class F>
  void forSamples(const DiffractionEdge& e, F&& visit) const;
  static uint64_t key(const glm::ivec3& c);

  float step_, cell_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
  std::vector<uint32_t> mark_;  ///< per edge, the last query that listed it
  uint32_t query_ = 0;
};

/// The edges in `candidates` (EdgeGrid::near) parallel to edges[i] (kParallelEdges), their
/// lines within `reach` (m) of its line beside it (over 0.1 mm away), overlapping it along its
/// length, neither i nor `other`; the `count` nearest, nearest first. Allocates.
std::vector<uint32_t> parallelNeighbours(const std::vector<DiffractionEdge>& edges, uint32_t i,
                                         uint32_t other, float reach, size_t count,
                                         const std::vector<uint32_t>& candidates);

/// The same for an edge e that need not be in `edges` (a moving object's, placed), skipping
/// the indices i and other (none: an index past edges).
std::vector<uint32_t> parallelNeighbours(const std::vector<DiffractionEdge>& edges,
                                         const DiffractionEdge& e, uint32_t i, uint32_t other,
                                         float reach, size_t count,
                                         const std::vector<uint32_t>& candidates);

}  // namespace dpc
