// First-order edge diffraction by the uniform theory of diffraction (UTD: R. G. Kouyoumjian &
// P. H. Pathak, "A uniform geometrical theory of diffraction for an edge in a perfectly
// conducting surface", Proc. IEEE 62(11), 1974; used for interactive acoustics by N. Tsingos,
// T. Funkhouser, A. Ngan & I. Carlbom, "Modeling acoustics in virtual environments using the
// uniform theory of diffraction", SIGGRAPH 2001), for acoustically hard wedges.
//
// Load time: the mesh's candidate edges: every edge shared by two non-coplanar triangles, and
// every edge used by one triangle only (the rim of an open surface, a thin screen: a
// half-plane, wedge 2 pi), unless it lies on another surface (a partition's rim along the
// floor is sealed). Per frame the wedge holding the source is the air wedge (the mesh's
// winding does not matter); it diffracts when wider than pi (a convex corner seen from the
// source: it can shadow). A room's inner corners, seen from inside, never do.
//
// Per frame and source: for every edge, the path source -> Q -> listener through the point Q
// of least length on the edge (Fermat: equal angles with the edge), kept when both legs are
// unoccluded and Q lies inside the edge. Its pressure per frequency is the UTD field
//   p_e = e^{-jkr}/r * D(phi, phi', beta0; k L) * sqrt(r / (s (r + s))) * e^{-jks}
// (r, s the legs, L = r s sin^2 beta0 / (r + s), D the four-term hard-wedge coefficient with
// the transition function F(X) = 2j sqrt(X) e^{jX} int_sqrt(X)^inf e^{-j t^2} dt). Continuity:
// the UTD field is built so that geometric-optics field + diffracted field is continuous at
// the shadow boundary; here the direct sound (when visible) and every edge path are summed
// coherently and |p|^2 is averaged over 16 frequencies per octave band (each path's phase at
// all 16, its UTD coefficient D, smooth across a band, at 4 and interpolated between), so the
// band energy is continuous when the listener crosses a shadow boundary, and distant paths (whose
// phases differ across the band) add as energies. The result replaces the direct sound: band
// intensity <|p|^2> / (4 pi) (the scale of 1/(4 pi r^2)), delay and direction those of the
// shortest contributing path. Air absorption multiplies each path's energy by exp(-m l).
// Paths that merge into one impulse arrive within (longest - shortest) path difference; the
// synthesis places them at the shortest path's delay (first order only; higher orders: see
// docs/validation.md).
//
// Reflections: inside a face's reflection zone (the listener sees the source's image in the
// face's plane) the face's specular reflection is the tracer's, added in energy, so the UTD
// term that corrects it at its boundary is left out of the coherent sum (it would stand
// alone, about minus half a reflection); outside the zone that term is the image source's
// diffraction and stays. The zone is the face's as it is, not as UTD takes it (without end):
// where the face ends before the reflection point (a 0.3 m reveal, the reflection point past
// its far edge), no reflection is traced and the term stays (engine/edge_path.h
// findAbsentReflections). With the line of sight free, an edge whose faces (without end, as
// UTD takes them) would put the listener in its shadow leaves out its shadow-boundary terms:
// its face ends before the line of sight, and the incident field they continue is there.
// Openings: the two edges of one face that runs along the line of sight
// (a thick wall's reveal, seen through its doorway) each count the opening's cut into the
// direct sound; together they count once (each takes half its field).
//
// Gaps: an edge path that passes a narrow gap (the frame's edge beside a closed door leaf, a
// free edge whose UTD field would count as if nothing else were near) takes the slit's field
// (engine/slit.h: Gomperts 1964, Mechel 1986) instead of the edge's, in the proportion
// slitWeight(k w, aspect); engine/gap_probe.h finds the gap's width w and how far it runs along
// the edge. A gap bounded by two edges counts once; a gap closed within 0.5 mm drops the path.
// A slit whose edges end before their point of least path length (a door's top gap or an
// undercut seen from beside the doorway) is found from the edge's end, on the surfaces of a gap
// already found or that block the line of sight.
// A gap along a narrow face (a box leaf's side, a wall's reveal up to 0.3 m) is a channel: the
// slit model with the gap's depth (engine/channel_path.h). An edge path whose leg
// threads a gap that such a slit carries (a thick wall's jamb seen through the gap beside a
// recessed leaf) is dropped: what passes there is that slit's.
// A line of sight through a gap (between two door leaves) keeps the direct sound only in the
// proportion 1 - s: the slit's field is driven by the incident pressure at its mouth and
// carries the rest.
// Edges in series: with the line of sight blocked, paths round two to four parallel edges (a
// pillar's corners, a door stop's and the reveal's) at a barrier's attenuation
// (engine/edge_chain.h), added to the sum in energy.
// Energy: an obstruction adds no energy to the path it blocks. With the line of sight blocked
// (lineOfSight() false), the result is held per band at the unobstructed direct sound and at
// the sum without the flat surfaces the line of sight crosses (a leaf ajar across a
// doorway's line of sight: the open doorway; engine/surface_bound.h; a flat surface: triangles
// joined by edges that do not diffract); through a slit, at the
// sum without either of its sides. With the line of sight free, the sum may exceed the direct
// sound by the lit side's Fresnel ripple (docs/estimators.md, "Gaps and slits" and "No energy
// added to a blocked path"). The paths' geometry is engine/edge_path.h, their sum
// engine/coherent_sum.h.
//
// Construction: control/propagation thread; allocates; no errors (degenerate triangles are
// skipped). apply(): propagation thread (the Tracer's occlusion queries); no errors.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "common/bands.h"
#include "engine/propagation.h"
#include "engine/tracer.h"
#include "engine/utd.h"
#include "scene/directivity.h"
#include "scene/scene.h"

namespace dpc {

/// One candidate diffracting edge: endpoints (m), the unit direction a -> b, the in-plane unit
/// vector of face 0 pointing away from the edge, face 0's unit normal (winding side), and
/// `open`, the angle (radians) from face 0 to face 1 turning toward normal0 (2 pi for a free
/// edge). The two wedges are open and 2 pi - open; the one holding the source is the air wedge,
/// and it diffracts (can shadow) when wider than pi, with UTD index n = wedge / pi. `surfaces`:
/// the flat surfaces (flatSurfaces, engine/diffraction_edges.h) of its face 0 and face 1 (the
/// same twice for a free edge).
struct DiffractionEdge {
  glm::vec3 a{0.f}, b{0.f};
  glm::vec3 direction{0.f}, face0{0.f}, normal0{0.f};
  float open = 0.f;
  float length = 0.f;
  std::array<uint32_t, 2> surfaces{0, 0};
  /// Its run (engine/finite_edge.h setEdgeRuns): from runFrom <= 0 to runTo >= length (m along
  /// `direction` from a), the collinear edges that continue it with the same faces included.
  /// Unbounded (an edge without end, UTD's) unless set.
  float runFrom = -std::numeric_limits<float>::infinity();
  float runTo = std::numeric_limits<float>::infinity();
  /// Whether the wave from beyond its run's ends is laid (engine/edge_path.h cornerPath): a
  /// thin sheet's edge that no other body's edge runs beside (engine/finite_edge.h
  /// markFreeEnds). False unless set.
  bool freeEnds = false;
};

/// Whether e is a free edge: a sheet's rim, one face, its wedge 2 pi.
inline bool isFreeEdge(const DiffractionEdge& e) {
  return e.open >= float(2.0 * std::numbers::pi) - 1e-4f;
}

/// rad: two faces within this angle of lying flat make no wedge (no diffracting edge).
inline constexpr double kFlatEdge = 0.05 * std::numbers::pi;

/// The bodies of a mesh's flat surfaces: per flat surface the number of its body, the
/// connected piece of mesh it belongs to (triangles sharing a corner, welded), numbered in the
/// order of their first triangles; and per body whether it is closed, a solid without a free
/// rim (a box leaf, a pillar); and per flat surface its extent when it stands free (m; +inf
/// when not: freeStandingExtents, engine/diffraction_edges.h). A box's six faces are one closed
/// body; a leaf welded to its frame is part of the frame's body.
struct SurfaceBodies {
  std::vector<uint32_t> body;  ///< per flat surface
  std::vector<bool> closed;    ///< per body
  std::vector<float> extent;   ///< per flat surface, m
  /// Per flat surface: its triangles' bounding box (m), and the candidate edges on its faces
  /// (indices into EdgeDiffraction::edges()).
  std::vector<std::pair<glm::vec3, glm::vec3>> box;
  std::vector<std::vector<uint32_t>> edges;
  std::vector<std::vector<uint32_t>> members;  ///< per body, its flat surfaces (ascending)
  /// Per body, +1 where its faces' normals (by their triangles' winding) point into the air,
  /// -1 for a solid object (closed, less than kSolidExtent across) wound inside out (its
  /// triangles enclose a negative volume): exporters differ, and a hit's normal times this
  /// points out of the solid whichever way it was wound. +1 for every other body (a room, a
  /// wall, a sheet), whose faces are taken as wound.
  std::vector<float> outward;
};

/// The band energy of the direct-plus-diffracted field is |p|^2 averaged over these
/// frequencies: kDiffractionFrequenciesPerBand log-spaced across octave band `band`
/// (i = 0 .. 15, the centres of equal log-frequency slices of the octave), Hz.
inline constexpr int kDiffractionFrequenciesPerBand = 16;
/// Frequencies per band where an edge path's UTD coefficient is evaluated; between them it is
/// interpolated (it is smooth across a band; the path's phase is not, and is evaluated at all
/// kDiffractionFrequenciesPerBand).
inline constexpr int kUtdAnchorsPerBand = 4;
double diffractionFrequencyHz(int band, int i);

/// The frequency index i (of diffractionFrequencyHz) of a band's UTD anchor a: the band's first
/// and last frequencies and evenly between. Any thread; no errors.
constexpr int utdAnchorIndex(int a) {
  return a * (kDiffractionFrequenciesPerBand - 1) / (kUtdAnchorsPerBand - 1);
}

/// A path's UTD coefficient (utdScaled, without the 1/sqrt(k) and the path's phase) at its
/// band's frequency i (0 .. kDiffractionFrequenciesPerBand - 1), from its values at the band's
/// anchors: linear in i (log-frequency) between them. D is smooth across a band (F(X) is
/// smooth in sqrt(X)), unlike the phase e^{-jkl}, which is evaluated at every frequency.
/// Against D at all 16 frequencies, the band intensities of the 256-talker dense hall's pairs
/// differ by 0.0017 dB RMS, 0.019 dB at most (63 Hz), at a quarter of the UTD evaluations;
/// tests/engine/utd_test.cpp holds band means over random wedges, angles and distances to
/// 0.005 dB RMS and 0.15 dB at most (0.003 / 0.10 dB measured). Any thread; no allocation; no
/// errors.
inline std::complex<double> interpolatedUtd(
    const std::array<std::complex<double>, kUtdAnchorsPerBand>& anchors, int i) {
  int a = 0;
  while (a + 2 < kUtdAnchorsPerBand && utdAnchorIndex(a + 1) <= i) ++a;
  const double t =
      double(i - utdAnchorIndex(a)) / double(utdAnchorIndex(a + 1) - utdAnchorIndex(a));
  return anchors[size_t(a)] + t * (anchors[size_t(a) + 1] - anchors[size_t(a)]);
}

/// Two edges bounding one narrow flat face (engine/channel_path.h): indices into the edges;
/// and the edges near each (engine/channel_turn.h setChannelNeighbours: where a channel may turn,
/// round a door stop), nearest first: near[0] round b (a channel running a to b leaves there),
/// near[1] round a.
struct NarrowFace {
  uint32_t a, b;
  std::array<std::vector<uint32_t>, 2> near{};
};

/// One moving object's edges (engine/object_edges.h): in its own frame, their neighbours for
/// chains (engine/edge_chain.h chainNeighbours), its narrow faces, and in the world at the pose
/// last placed
/// (surfaces both kMovingObjects: no flat surface of the static mesh).
struct ObjectEdges {
  std::vector<DiffractionEdge> local;
  std::vector<std::vector<uint32_t>> near;
  /// Its narrow faces (engine/channel_path.h narrowFaces, in `local`'s numbering; `near` left
  /// empty: the static edges a channel turns round are found per query, the object moving).
  std::vector<NarrowFace> faces;
  std::vector<DiffractionEdge> world;
  glm::vec3 centre{0.f};  ///< of a sphere holding the placed edges (m)
  float radius = 0.f;     ///< m
};

struct BoundQuery;
struct EdgeChain;
struct EdgePath;

class EdgeDiffraction {
 public:
  /// Finds the diffracting edges of the mesh, and of each moving object's mesh (placed at its
  /// first keyframe's pose, as the tracer starts).
  explicit EdgeDiffraction(const Mesh& mesh, const std::vector<ObjectDesc>& objects = {});

  /// Places object k's edges at poses[k] (the tracer's poses this frame; objects past the
  /// list keep theirs). Propagation thread, between frames (not while apply() runs);
  /// allocates only the first time.
  void setObjectPoses(const std::vector<Pose>& poses);

  const std::vector<DiffractionEdge>& edges() const { return edges_; }
  /// Per static mesh triangle, its flat surface (flatSurfaces, engine/diffraction_edges.h).
  const std::vector<uint32_t>& surfaces() const { return surfaces_; }
  /// The static mesh's flat surfaces' bodies (surfaceBodies, engine/diffraction_edges.h).
  const SurfaceBodies& bodies() const { return bodies_; }

  /// Replaces `direct` by the direct sound plus every first-order edge and slit path from
  /// source to the listener centre and, with the line of sight blocked, every path round edges
  /// in series (engine/edge_chain.h; a moving object's edges too, one or more: objects have no
  /// first-order paths; direct.chainsLeftOut counts what its caps left out) (see
  /// the file comment). speedOfSound in m/s, airPerMetre the energy attenuation per metre per
  /// band. Returns the number of edge paths (unoccluded, Q inside its edge, its gap not closed)
  /// and chains used; 0 leaves `direct` as it was. Reentrant: concurrent calls (one per
  /// listener) are safe; allocates its lists of paths and probe rays. A directional source
  /// (scene/directivity.h, forward a unit vector) scales each path's energy by its weight
  /// toward its edge point Q (a slit path too; a chain toward its first edge); `direct` must
  /// carry its own weight already (Propagator::directSound does). Omni (the default): no
  /// weight. usedEdges, when given, receives the index in edges() of each edge path counted,
  /// then each static chain's edges (not a moving object's), in order (cleared first; it
  /// allocates only while it grows).
  size_t apply(const Tracer& tracer, const glm::vec3& source, const ListenerSphere& listener,
               float speedOfSound, const Bands& airPerMetre, DirectSound& direct,
               const Directivity& directivity = {},
               const glm::vec3& forward = glm::vec3(1.f, 0.f, 0.f),
               std::vector<uint32_t>* usedEdges = nullptr) const;

 private:
  /// A query from source to L (m) over this mesh's surfaces, bodies and edges, nothing laid.
  BoundQuery newQuery(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
                      float speedOfSound, const Bands& airPerMetre, const Directivity& directivity,
                      const glm::vec3& forward) const;
  /// The edge and slit paths and, with the line of sight blocked, the chains from query.source
  /// to query.L; query.crossed is found unless set (a slit's side taken as closed).
  void layPaths(bool lineOfSight, BoundQuery& query, std::vector<EdgePath>& paths,
                std::vector<EdgeChain>& chains, uint32_t& chainsLeftOut) const;
  /// The direct sound's band intensity (1/m^2) with the line of sight taken as blocked by the
  /// side of `slit`, the slit it passes free (open: that query): a line of sight through a
  /// 3 mm slot between two slats hears at least what it would with the slot shut, as a
  /// listener a centimetre over, behind a slat, does (the ways round the screen). leftOut
  /// counts the chains its caps left out.
  Bands slitClosedIntensity(const EdgePath& slit, const BoundQuery& open, const DirectSound& direct,
                            uint32_t& leftOut) const;

  std::vector<uint32_t> surfaces_;  ///< per mesh triangle, its flat surface
  SurfaceBodies bodies_;            ///< the flat surfaces' bodies (surfaceBodies)
  std::vector<DiffractionEdge> edges_;
  std::vector<NarrowFace> narrow_;  ///< faces a channel may run along (engine/channel_path.h)
  /// Per edge, the edges a path round edges in series may take next (engine/edge_chain.h).
  std::vector<std::vector<uint32_t>> chainNear_;
  std::vector<ObjectEdges> objects_;  ///< per moving object, its edges (engine/object_edges.h)
};

}  // namespace dpc
