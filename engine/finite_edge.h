// An edge's finite length in its first-order path's field. UTD (engine/utd.h) takes every edge
// as infinite: its coefficient is the stationary-phase value of the edge's line of secondary
// sources, which holds when the edge runs on past its first Fresnel zone both ways from Q. A
// short edge (a free-standing panel's top, a table's side, a doorway's lintel at 63 Hz) holds
// only part of that zone and diffracts less; each of its ends adds a corner's wave. Each of the
// four UTD terms D_i is therefore taken as the infinite edge's times
//
//   T_i(k) = 1 - w_i1 G(a_1 sqrt(k zone)) - w_i0 G(|a_0| sqrt(k zone)),
//   G(x) = int_x^inf e^{-j t^2} dt / int_-inf^inf e^{-j t^2} dt   (G(0) = 1/2, G(inf) = 0),
//
// a_0 <= 0 <= a_1 the ends' distances from Q along the edge (m), zone the along-edge curvature
// of the path length, sin^2 beta (r + s) / (2 r s) (1/m), so that the path over the point z
// from Q is longer by zone z^2. w_ie is the Biot-Tolstoy-Medwin line integrand's term i at end
// e over its value at Q (U. P. Svensson, R. I. Fred, J. Vanderkooy, "An analytic secondary
// source model of edge diffraction impulse responses", JASA 106(5), 1999, eqs. 8-10: the term
// sin(nu psi_i) / (cosh(nu eta) - cos(nu psi_i)) over m l). Near its shadow or reflection
// boundary a term's integrand peaks at Q and the ends matter little to it; far from every
// boundary it is flat and T_i is the Fresnel integral over [a_0, a_1]. That is the first term
// of the end-point expansion of each term's BTM integral (exact for a flat integrand). The
// edge's field is sum_i D_i T_i = D - G(end 1) D^(1) - G(end 0) D^(0), D^(e) the UTD sum with
// each term's cotangent weighted by w_ie (EdgeEnds::terms).
//
// An edge's run is the edge and the collinear edges that continue it as the same wedge (a
// wall's top split by the mesh's triangulation is one run).
//
// Only a thin sheet's edges (a free edge, faces 2 pi apart: a panel, a leaf, a thin wall's
// doorway) take the factor; they are checked against the BTM line integral of a thin screen
// (tests/engine/finite_edge_test) and dpc-wave's FDTD. A wedge's edges (a thick wall's reveal,
// a box) stay infinite: tried on them too, a 0.3 m deep doorway on the line of sight fell 4 dB
// further below a thin one at 63 Hz, where dpc-wave reads the two alike.
//
// Internal to the engine (edge_path, coherent_sum). Any thread; setEdgeRuns allocates, the rest
// does not; no errors.
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <glm/vec3.hpp>
#include <limits>
#include <vector>

#include "engine/diffraction.h"
#include "engine/utd.h"

namespace dpc {

/// A first-order path's edge ends: where they lie from its point Q, and its UTD terms weighted
/// by what the BTM integrand holds there. Infinite ends (the default) leave the UTD field as it
/// is.
struct EdgeEnds {
  /// m along the edge's direction from Q to the run's two ends: at[0] <= 0 <= at[1].
  std::array<float, 2> at{-std::numeric_limits<float>::infinity(),
                          std::numeric_limits<float>::infinity()};
  /// Per end, the path's UTD terms with each cotangent times w_ie (in [0, 1]; all 0 for an
  /// infinite end), and their order sums (utdTermSums): D^(e) = utdScaled(terms[e], sums[e], ..).
  std::array<std::array<UtdTerm, 4>, 2> terms{};
  std::array<UtdTermSums, 2> sums{};
  /// sin^2 beta (r + s) / (2 r s), 1/m: the path over the edge's point z (m) from Q is longer
  /// by zone z^2.
  double zone = 0.0;
  /// Q lies beyond the run on its line (a corner path, engine/edge_path.h cornerPath): both
  /// ends on one side, the field G(|a_near|) D^(near) - G(|a_far|) D^(far), without D itself.
  bool outside = false;
  /// Whether either end is finite (otherwise the field is the infinite edge's).
  bool finite() const { return outside || std::isfinite(at[0]) || std::isfinite(at[1]); }
};

/// Sets every edge's run (DiffractionEdge::runFrom, runTo): the edges joined end to end along
/// one line whose faces are the same flat surfaces at the same angles.
void setEdgeRuns(std::vector<DiffractionEdge>& edges);

/// Sets DiffractionEdge::freeEnds: a free edge (a thin sheet's rim, faces 2 pi apart) of a
/// small body (smallBody: a panel, not a wall) none of whose edges has a parallel neighbour
/// within kChainReach (`near`, chainNeighbours) on another body. A door leaf's rims run beside
/// its frame's edges, a few millimetres off: its corners are the gaps' (engine/slit.h), and a
/// leaf that is a moving object has no first-order paths at all, so the same leaf in the mesh
/// takes none either.
void markFreeEnds(const SurfaceBodies& bodies, const std::vector<std::vector<uint32_t>>& near,
                  std::vector<DiffractionEdge>& edges);

/// The ends of edge `e`'s run seen from a path's point Q (unbounded unless e is a free edge) (m, on
/// the edge) between `source` and `L`, with the path's wedge angles (radians: phiS, phiL from face
/// 0, the air wedge `wedge`) and UTD terms (those with cot 0 are left out: the sum drops them).
EdgeEnds edgeEnds(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
                  const glm::vec3& L, double phiS, double phiL, double wedge,
                  const std::array<UtdTerm, 4>& terms);

/// G(|a_e| sqrt(k zone)) above for both ends at wavenumber k (rad/m); 0 for an infinite end.
std::array<std::complex<double>, 2> endTails(const EdgeEnds& ends, double k);

/// The path's field from its UTD sum D and its end sums D^(e) at one k, given their ends'
/// tails g = endTails(ends, k): D - g_1 D^(1) - g_0 D^(0), or outside the run
/// g_near D^(near) - g_far D^(far).
std::complex<double> withEnds(const EdgeEnds& ends, const std::array<std::complex<double>, 2>& g,
                              std::complex<double> d,
                              const std::array<std::complex<double>, 2>& dEnds);

/// withEnds(ends, endTails(ends, k), d, dEnds) / d (1 where d is 0 or no end is finite).
std::complex<double> finiteEdgeFactor(const EdgeEnds& ends, double k, std::complex<double> d,
                                      const std::array<std::complex<double>, 2>& dEnds);

}  // namespace dpc
