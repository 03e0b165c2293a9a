// What the scene's surfaces allow the coherent sum of the direct sound and the edge paths
// (engine/diffraction.h): an obstruction adds no energy to the path it blocks. The sum is
// compared with the same sum with surfaces taken away (a flat surface of the mesh,
// engine/diffraction_edges.h flatSurfaces: a door leaf is one): the edges of their faces
// dropped (an edge whose other face stays is that face's free rim: a leaf welded to its frame
// at the hinge taken away leaves the jamb), the paths they alone hid or closed restored, the
// gaps they closed opened.
//
// Internal to the engine. Propagation thread (the Tracer's queries); allocates; no errors.
#pragma once

#include <cstdint>
#include <deque>
#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"
#include "engine/diffraction_edges.h"
#include "engine/edge_path.h"
#include "engine/propagation.h"
#include "engine/tracer.h"
#include "scene/directivity.h"

namespace dpc {

/// The most a knife edge's lit-side Fresnel ripple raises the field (energy ratio, +1.37 dB:
/// the first maximum of |F(v)|^2, 1.17^2, of the half-plane's Fresnel diffraction).
inline constexpr float kLitRipple = 1.37f;

/// Stands for every moving object's triangles among the surfaces a segment crosses: objects
/// have no first-order edge paths (only chains round them, engine/object_edges.h), and one of
/// them in the way is taken away with the others.
inline constexpr uint32_t kMovingObjects = 0xffffffffu;

/// The flat surface of a triangle in the Tracer's numbering (`surfaces`, per mesh
/// triangle; kMovingObjects past them).
uint32_t surfaceOf(const std::vector<uint32_t>& surfaces, uint32_t triangle);

/// The flat surfaces of the static mesh (`surfaces`, per triangle; kMovingObjects for an
/// object's) that the segment `ray` crosses, sorted and each once, into out; false past
/// kMaxCrossings crossings.
bool crossedSurfaces(const Tracer& tracer, TraceRay ray, const std::vector<uint32_t>& surfaces,
                     std::vector<uint32_t>& out);

/// A path one of whose legs is blocked, and the surfaces that block its legs, found when first
/// asked (`searched`; none known: `known` false, never reopened).
struct HiddenPath {
  EdgePath path;
  std::vector<uint32_t> by;
  bool searched = false;
  bool known = false;
};

/// Everything heldBound uses besides the paths: the query, the paths a leg of which is blocked,
/// and those whose gap is closed (EdgeDiffraction::apply fills them).
struct BoundQuery {
  const Tracer& tracer;
  glm::vec3 source, L;
  const std::vector<uint32_t>& surfaces;      // per mesh triangle, its flat surface
  const SurfaceBodies& bodies;                // the flat surfaces' bodies (surfaceBodies)
  const std::vector<DiffractionEdge>& edges;  // the mesh's candidate edges
  std::deque<DiffractionEdge> rims;  // edges left with one face when the other's surface went
  std::vector<HiddenPath> hidden;
  std::vector<EdgePath> closed;  // paths whose gap is closed (findSlits)
  /// The flat surfaces the line of sight crosses, sorted (crossLineOfSight); empty when it is
  /// free or they are not known.
  std::vector<uint32_t> crossed;
  float speedOfSound;
  Bands airPerMetre;
  const Directivity& directivity;
  glm::vec3 forward;
  /// With the line of sight free, what the small bodies near it leave the sum at least, per
  /// band (1/m^2; heldBound fills it, 0 where none is small).
  Bands smallFloor{0.f};
  /// The scene has moving objects (their edges have no first-order paths of their own).
  bool objects = false;
  /// The flat surfaces (sorted) of the small bodies whose hull the chains looked for ways round
  /// (engine/hull_ways.h: those the line of sight crosses and those joined to them): a hull's
  /// way passes round them all, so its bound takes them all away (laidChains sets it).
  std::vector<uint32_t> hullSurfaces{};
};

/// Fills q.crossed: the flat surfaces the segment from q.source to q.L crosses, when the line
/// of sight is not free (empty when it is, or past crossedSurfaces's limit).
void crossLineOfSight(bool lineOfSight, BoundQuery& q);

/// The paths as they would be with the surfaces in `removed` (sorted) taken away: the edges
/// of their faces dropped, an edge whose other face stays made its rim (addRims); the paths
/// they alone hid, and those whose gap they alone closed, restored; the gaps they closed opened
/// (free edges); the slits' owners, the reveals and the terms (for a line of sight free or not) set
/// again.
std::vector<EdgePath> pathsWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                                   const std::vector<uint32_t>& removed, bool lineOfSight);

/// The coherent sum with the surfaces `removed` taken away (pathsWithout) and the direct sound
/// d (through a slit the line of sight still passes, if any), in the first `bands` bands.
Bands sumWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                 const std::vector<uint32_t>& removed, const DirectSound& d,
                 int bands = kNumBands);

/// The surfaces (sorted) with every surface of each closed body among them added (a solid
/// goes whole: taken away face by face, a box's side faces would float in the air), sorted.
std::vector<uint32_t> wholeSolids(const std::vector<uint32_t>& surfaces,
                                  const SurfaceBodies& bodies);

/// What the surfaces allow the coherent sum, per band: an obstacle adds no energy to the path
/// it blocks, so
///  - with the line of sight blocked (coherent.visible false), at most the sum without the
///    surfaces it crosses (q.crossed, crossLineOfSight), the line of sight free (a leaf ajar across
///    a doorway's line of sight: at most the open doorway), at most the sum without any one of
///    them, the others still in the way (a leaf beside a jamb, the line of sight through both:
///    at most the doorway without the leaf; a closed body's faces, a box leaf's, go together),
///    and at most the direct sound with nothing in its
///    way (`free`, 1/m^2); `free` alone when those surfaces are not known;
///  - with the line of sight through a slit (`throughSlit`, slitOnLineOfSight), at most the
///    sum without either of the slit's two sides (the slit is narrower than what either leaves
///    open; a double door's leaves seen through the gap between them);
///  - free or blocked, in each band whose wavelength exceeds the extent (SurfaceBodies) of a
///    flat surface the line of sight does not cross, at most kLitRipple times the sum without
///    that surface (a closed body's surfaces together). UTD is an
///    asymptotic theory: each edge's term is an infinite edge's, as strong as the surface is
///    large. A surface smaller than the wavelength scatters as a whole and weakly (Rayleigh), its
///    edges' terms largely cancelling, which first-order terms summed edge by edge miss: a
///    door leaf swung 70 to 85 degrees beside a doorway's line of sight read 6 to 9 dB above
///    the open doorway at 63 Hz where a wave simulation of the same scene reads it within
///    1.5 dB (docs/validation.md, "Doors against a wave simulation").
/// `sum`: the coherent sum itself (the small-surface bound is skipped where a surface's own
/// paths are too weak to matter). Without a bound, 1e30 in every band. Band intensities in
/// 1/m^2 (coherentIntensity's scale).
Bands heldBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                const EdgePath* throughSlit, const Bands& free, const Bands& sum, BoundQuery& q);

/// A path round edges in series (engine/edge_chain.h) as the bounds see it: its band energy
/// (1/m^2) and the flat surfaces its edges lie on.
struct ChainEnergy {
  Bands energy{0.f};
  std::vector<uint32_t> surfaces;
};

/// What the surfaces allow the held sum (heldBound) with the paths round edges in series added
/// in energy, the line of sight blocked (coherent.visible false) by the surfaces q.crossed: at
/// most `free` (1/m^2, the unobstructed direct sound); when only small bodies (not largeBody:
/// a leaf, a crate, a pillar; two pillars in a row) and moving objects block it, at most the
/// scene without them all (each body taken away whole, a pillar meshed as an open tube too),
/// the line of sight free; when a large body's face is crossed too (a wall with the leaf ajar
/// in its doorway), per small body and for the moving objects together at most the sum
/// without them plus the chains that touch none of their surfaces (a moving object's chains
/// touch kMovingObjects). A leaf ajar across a doorway's line of sight, in the mesh or an
/// object, is no louder than the open doorway, whatever its chains round the leaf's free edge
/// give (a barrier's attenuation over the free field, blind to the doorway's own edges). A
/// large body's faces are not taken away here: without one face of a wall the chains through
/// its doorway would be left out, and without the faces a column's line of sight crosses, its
/// side faces' rims would stand in the free field as two plates. 1e30 in every band where no
/// bound applies.
Bands chainBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                 const Bands& free, const std::vector<ChainEnergy>& chains, BoundQuery& q);

}  // namespace dpc
