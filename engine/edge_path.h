// One first-order edge path source -> Q -> listener over a diffracting edge (engine/diffraction.h):
// where Q lies, its UTD terms, its legs, and the slit it may pass; and the marks a list of paths
// takes together (a slit found from both its edges, a reveal's two edges).
//
// Internal to the engine (engine/diffraction.cpp, coherent_sum, surface_bound). Any thread;
// no allocation except markers' scratch; no errors.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <vector>

#include "engine/diffraction.h"
#include "engine/finite_edge.h"
#include "engine/slit.h"
#include "engine/tracer.h"
#include "engine/utd.h"

namespace dpc {

/// m: keeps occlusion tests off an edge's own faces.
inline constexpr float kLegEpsilon = 1e-3f;

/// Cosine of the angle within which two edges count as parallel (two slits' edges, a channel's
/// back edge and the edge it turns to).
inline constexpr float kParallelEdges = 0.99f;

/// m: how far inside its nearer end an atEnd path's point Q lies (edgePath).
inline constexpr float kEndMargin = 0.01f;

/// How far past a corner path's nearer end its Q may lie, in Fresnel units (the end's distance
/// times sqrt(k zone), engine/finite_edge.h) at the lowest band's lowest frequency: beyond 1.5
/// the run's field is under 0.18 of an infinite edge's (|G(1.5)| = 0.176; |G(3)| = 0.093).
inline constexpr double kCornerReach = 1.5;

/// A gap's closing surface when the probe did not say (no flat surface has this number).
inline constexpr uint32_t kUnknownSurface = 0xfffffffeu;

/// One first-order edge path source -> Q -> listener: its frequency-independent parts, and
/// the slit it passes when its edge bounds a narrow gap.
struct EdgePath {
  double length;                 // r + s, m
  double distanceParameter;      // L = r s sin^2 beta0 / (r + s), m
  double spreading;              // 1/r sqrt(r / (s (r + s))), 1/m
  double prefactor;              // utdPrefactor(n, sin beta0)
  std::array<UtdTerm, 4> terms;  // frequency-independent parts of D
  UtdTermSums sums;              // the terms' asymptotic order sums (utdTermSums)
  float legs;                    // r + s in single precision, m
  glm::vec3 arrival;             // unit vector from the listener toward Q
  glm::vec3 leaving;             // unit vector from the source toward Q
  const DiffractionEdge* edge;
  glm::vec3 q;                // the point on the edge, m
  glm::vec3 mouth;            // unit direction across the gap the path may pass
  glm::vec3 turn;             // the air wedge turns from face0 toward this (+-normal0)
  float airWedge;             // the air wedge's angle, radians
  float gapWidth = 0.f;       // m; 0: a free edge (engine/gap_probe.h)
  bool slitOwner = false;     // carries its slit's field (once per slit)
  SlitPath slit;              // valid when gapWidth > 0
  glm::vec3 slitCentre{0.f};  // the slit path's point on the slit's centre line, m
  double slitAspect = 0.0;    // slit length / width, as probed (0 to 8)
  double share = 1.0;         // of its UTD field: 1/2 for each edge of a reveal (markReveals)
  /// The path-length excess (m) of the detour round another edge one of its legs just clears
  /// (a pillar's far corner past its near one's path: engine/edge_chain.h grazeExcess); the
  /// field takes that edge's lit-side transition (grazingAmplitude). Negative: none.
  float grazeExcess = -1.f;
  float grazeSpan = 0.f;  ///< m: how far from its edge that other edge lies
  double phiS = 0.0, phiL = 0.0, wedge = 0.0;  // wedgeAngles' angles, radians
  /// Its edge's run's ends seen from Q (engine/finite_edge.h): the UTD field times
  /// finiteEdgeFactor. Unbounded for a path without a UTD field.
  EdgeEnds ends;
  /// Per face of its wedge (0: at angle 0, the edge's face 0; 1: at `wedge`, its face 1),
  /// whether the face is there to reflect where the listener sees the source's image in its
  /// plane (findAbsentReflections); where it is not (a reveal 0.25 m deep, the reflection
  /// point past its far edge), no reflection reaches the listener and the face's
  /// reflection-boundary term stays in the sum (setTerms).
  std::array<bool, 2> reflects{true, true};
  /// A corner path (cornerPath): Q lies beyond its edge's run on the edge's line, the legs
  /// are tested to the run's end (q), and the field is that of the run alone (ends.outside).
  bool corner = false;
  uint32_t gapCloser = kUnknownSurface;        // the surface that closes its gap (surface_bound.h)
  bool atEnd = false;  // no UTD field (share 0), a slit's only: Q at the edge's end, a
                       // channel, a turned leg, an opening's own path
  /// The spread (m, a standard deviation) of its slit field's path length where the slit stands
  /// for an opening whose shape is not traced (a chain's opening beside a leaf's rim:
  /// engine/openings.h): its field adds coherently by exp(-(k sigma)^2 / 2) of its pressure,
  /// the rest in energy. Zero for every other path.
  float phaseSpread = 0.f;
  /// A channel's (engine/channel_path.h) offset from its front mouth's point Q to its back
  /// mouth's, m (the slit's depth across the face it runs along); zero for every other path.
  glm::vec3 through{0.f};
  /// A channel that turns past its back mouth (between a box leaf's back face and the door
  /// stop it closes against: engine/channel_turn.h turnedChannel): the offset from the back
  /// edge to the edge where it leaves, m; zero for a straight channel and every other path.
  glm::vec3 beyond{0.f};
  /// The same at its front mouth (a door stop on the source's side): the offset from the edge
  /// where it enters to Q, so the source's leg ends at Q - before - lipBefore; zero for every
  /// other path.
  glm::vec3 before{0.f};
  /// The widths of the narrow legs `before` and `beyond` (m; zero where there is none): a
  /// leg wider than the slit adds less to its depth (channelDepth).
  std::array<float, 2> legWidth{0.f, 0.f};
  /// Past a turn, the leg round the door stop's lip to the stop's far edge, where the listener
  /// (lipBeyond) or the source (lipBefore) is seen from (m): free air, not part of the slit's
  /// depth; zero when the turn's edge sees them.
  glm::vec3 lipBefore{0.f}, lipBeyond{0.f};
  /// The free legs' path-length excess over the straight line from the slit's mouth at each
  /// end (m; SlitPath::shadowExcess).
  std::array<float, 2> lipExcess{0.f, 0.f};
  /// The free legs' lengths at each end (m; ChannelTurns::lipBeforeLength, lipBeyondLength):
  /// the slit's legs run them as well as the straight lines from their ends.
  std::array<float, 2> lipLength{0.f, 0.f};
  /// A channel's narrow face, the flat surface it runs along (its front and back edges'
  /// common face): taking away the front edge's other face (a wall's face round its reveal)
  /// leaves the channel; kUnknownSurface for every other path.
  uint32_t face = kUnknownSurface;
  /// The two surfaces either side of a gap one of its legs threads away from Q (the leaf and
  /// the reveal beside a thick wall's jamb; engine/diffraction.cpp, markThreads); none:
  /// kUnknownSurface.
  std::array<uint32_t, 2> threadedBy{kUnknownSurface, kUnknownSurface};
  /// How far along the edge from Q the slit is seen from both ends (m, relative to Q; a channel
  /// whose point of least length is hidden: engine/channel_path.h visibleChannel); unbounded
  /// for every other path.
  /// A channel along a large body's face (a wall's reveal beside a leaf set in it, a moving one
  /// too): its slit is as deep as the gap's far side stands along it (measured by the probe),
  /// not as the face is wide.
  bool measuredDepth = false;
  /// A small body's channel whose gap's far side stands along part of its face: its slit is
  /// as deep as that part (engine/path_slits.cpp).
  bool farSideAlong = false;
  float visibleFrom = -std::numeric_limits<float>::infinity();
  float visibleTo = std::numeric_limits<float>::infinity();
};

/// Edge e's two faces' in-plane unit vectors pointing away from it: face 0's, and face 1's at
/// angle `open` from it toward normal0 (a free edge's face 1 is face 0's continuation).
std::array<glm::vec3, 2> faceDirections(const DiffractionEdge& e);

/// True when edges a and b are the two ends of one flat face: parallel, and the line across
/// from a to b runs along one of a's faces and back along one of b's (a reveal of a thick wall,
/// a slab's two rims).
bool joinedByFace(const DiffractionEdge& a, const DiffractionEdge& b);

/// The narrowest air wedge that diffracts (radians): wider than pi by a margin, so a corner
/// folded by less than 9 degrees (flat within rounding) or a room's inner corner seen from
/// inside never does.
inline constexpr double kConvexWedge = 1.05 * 3.14159265358979323846;

/// The angle (radians, in [0, 2 pi)) of point p about edge e at q, in the plane square to the
/// edge, from face 0 toward normal0.
double faceAngle(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& p);

/// True when x lies within edge e's length (its foot on e's line strictly between e's ends).
bool withinEdge(const DiffractionEdge& e, const glm::vec3& x);

/// The air wedge around edge e at Q: the angles (radians, from face 0 in the plane perpendicular
/// to the edge) of the source and of the point `other`, measured in the wedge that holds the
/// source, that wedge's angle and its sense (+1: from face 0 toward normal0, -1: the other
/// way); true when `other` lies inside that wedge and the wedge is wider than about pi (a
/// convex edge, which can shadow).
bool airWedge(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
              const glm::vec3& other, double& phiS, double& phiOther, double& wedge,
              double& sense);

/// Where Q lies beyond the end of a thin sheet's edge run (a panel's top seen from beside the
/// panel), the wave from the run itself, its corner's: the path through Q on the edge's line
/// (length, angles, UTD terms there; every term kept, the run excluding Q), its field the
/// run's integral (EdgeEnds::outside), q the run's end, where the legs are tested. Only
/// where the end lies within kCornerReach of Q (Fresnel units at the lowest band's lowest
/// frequency). False otherwise, for an edge without DiffractionEdge::freeEnds (a wedge's, a
/// door leaf's beside its frame), or for one that does not hold its run's end on that side.
bool cornerPath(const DiffractionEdge& e, const glm::vec3& source, const glm::vec3& L,
                bool directVisible, EdgePath& p);

/// The path over edge e from source to the listener centre L through the point Q of least
/// length, its legs not yet tested (legsFree); false when Q lies outside the edge or the wedge
/// cannot diffract toward L. With atEnd, only where Q lies beyond the edge: Q is then put
/// kEndMargin (at most 1 % of the edge) inside its nearer end, and the path has no UTD field
/// (share 0, atEnd), only the field of a slit its edge may bound (the slit is a line source
/// along its whole extent: its field from beyond the stationary point, engine/slit.h).
bool edgePath(const DiffractionEdge& e, const glm::vec3& source, const glm::vec3& L,
              bool directVisible, EdgePath& p, bool atEnd = false);

/// p's UTD terms from its angles, with the terms the tracer or a free line of sight make
/// absent left out, and their order sums.
void setTerms(bool directVisible, EdgePath& p);

/// A channel's slit depth (m): the length of its gap's centre line, across the face it runs
/// along (|through|) and, where it turns, along and then square to that direction (a door stop's
/// turn: the centre line runs along the leaf's face to the middle of the gap behind it, then
/// along that gap to the stop's edge; with the two gaps equally wide its length is the
/// leaf's thickness plus the stop's lip); a turned leg wider than the slit counted at its
/// length times p.gapWidth over its width (legWidth), the depth of the slit's width with the
/// same inertance; 0 for other paths.
double channelDepth(const EdgePath& p);

/// The path's two legs, source -> Q and Q -> L (for a channel, source -> Q - before - lipBefore
/// and Q + through + beyond + lipBeyond -> L), each stopping
/// kLegEpsilon short of its ends (the listener sphere itself is not geometry).
std::array<TraceRay, 2> legRays(const glm::vec3& source, const glm::vec3& L, const EdgePath& p);

/// Sets p.reflects for each face whose reflection zone, as UTD takes the face (without end),
/// holds the listener: whether the face holds the point where the source's image in its plane
/// is seen from L (a short ray across the plane there, the point taken at least 1 mm from
/// p's own edge, where its face is, and again 0.01 mm back toward the edge, so that a point on
/// the far edge's line counts as on the face), then sets p's terms and ends again. Anything in
/// the face's plane there counts (a coplanar leaf shut in its doorway too; a bound that takes
/// that leaf away keeps the flag). A corner path, a path without a UTD field (atEnd) or without
/// an edge is left as it is. Propagation thread; up to four occlusion rays; no allocation.
void findAbsentReflections(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
                           bool directVisible, EdgePath& p);

/// True when nothing blocks either leg of p.
bool legsFree(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L, const EdgePath& p);

/// Fills p's slit from its gap: the slit's centre line runs along the edge, half the width
/// across the mouth, from `from` to `to` m along it relative to Q (where the gap ends,
/// engine/gap_probe.h); its stationary point, legs and angles as engine/slit.h defines them.
void makeSlit(const glm::vec3& source, const glm::vec3& L, float from, float to, EdgePath& p);

/// Gives p a slit `width` m wide along its edge's whole extent (an opening whose extent the
/// probe did not measure), its aspect the edge's length over the width (at most
/// kSlitFullAspect), its legs to `source` and `L` as makeSlit's.
void slitAlongEdge(float width, const glm::vec3& source, const glm::vec3& L, EdgePath& p);

/// The slit model's share s of path p's pressure at wavenumber k (rad/m): engine/slit.h
/// slitWeight at X = k sin(beta) w for p's slit and aspect. p must have a slit (gapWidth > 0).
double slitShare(const EdgePath& p, double k);

/// Makes p the other side of the slit `from` carries (a free edge across it: its UTD field is
/// that slit's other edge, which the slit's field replaces in the proportion s): from's width,
/// slit, centre and aspect, closed by from's edge's surface; p does not carry the field.
void takeSlit(EdgePath& p, const EdgePath& from);

/// Whether flat surfaces s and t are one or on one body (`body`: per flat surface, its body,
/// SurfaceBodies::body); a surface past body.size() (a moving object's, or none) only equals
/// itself.
bool sameBody(const std::vector<uint32_t>& body, uint32_t s, uint32_t t);

/// Whether flat surface s is on the body of either of edge e's faces (sameBody; moving
/// objects' surfaces are not told apart from each other).
bool onEdgeBody(const std::vector<uint32_t>& body, const DiffractionEdge& e, uint32_t s);

/// True when p's edge lies across o's slit: parallel to o's edge, on the surface that closes it,
/// p's point on o's mouth side and within 2.5 widths of o's (the probe met that surface within
/// one width, p's edge within 1.5 more; seen at a slant, the legs meet it in its shadow short of
/// the opening's width: a leaf ajar 9 degrees, its rim 7 cm from the jamb, the jamb's probe
/// reads 3.6 cm). A leaf's free edge across the opening from the jamb whose probe met the leaf.
/// With `body` (per flat surface, its body: SurfaceBodies::body), an edge on
/// another face of the closing surface's body counts too (a box leaf ajar 15-20 degrees: the
/// probe from the jamb meets its front face; the rim across the opening is its back corner).
bool acrossSlit(const EdgePath& o, const EdgePath& p,
                const std::vector<uint32_t>* body = nullptr);

/// A slit bounded by two edges (a leaf's rim and its frame's) is found from both; only one
/// carries its field: the shallowest (a sheet's rim before the reveal beside it, a box leaf's
/// side face before the wall's reveal), the first of equals, but for a path without depth at
/// the mouth of a small body's channel whose far side stands along its face and which reads
/// the gap no wider (the channel carries it: a leaf's latch face half out of the reveal, and
/// the path round the jamb's corner beside it). Same slit: parallel edges whose
/// centre lines (a channel's, from its front mouth to its back one) lie within half the wider
/// gap (plus 1 mm) of each other, or one across the other's slit (acrossSlit: an oblique
/// leaf's free edge and the jamb measure the opening between them differently; with `body`,
/// per flat surface its body, an edge on another face of the closing body too: a box leaf's
/// latch channel in the static mesh and the jamb's path whose probe met the leaf's front face).
void markSlitOwners(std::vector<EdgePath>& paths, const std::vector<uint32_t>* body = nullptr);

/// The two edges of one face that both diffract the path, the face running along the line of
/// sight between source and L (the near and far edges of a thick wall's doorway seen through it,
/// the face within kAlongSight of that line), bound one side of one opening: each first-order
/// path counts the opening's cut into the direct sound, and both together count it twice
/// (through a 0.3 m wall, the doorway read 9 dB above the Kirchhoff aperture integral at 63 Hz
/// and 5 dB at 125 Hz). Like a slit found from both its edges, that side counts once: each
/// edge takes half. A face seen at a wider angle (a solid wedge's face toward its far rim, 26°
/// from the line in diffraction_test) is not such a pair.
void markReveals(const glm::vec3& source, const glm::vec3& L, std::vector<EdgePath>& paths);

/// The index in `edges` of path p's edge; edges.size() for an edge not in it (a moving
/// object's, placed: engine/object_edges.h).
size_t edgeIndex(const std::vector<DiffractionEdge>& edges, const EdgePath& p);

}  // namespace dpc
