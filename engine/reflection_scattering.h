// A traced ray's reflection off a free-standing face smaller than its first Fresnel zone: the
// share of each octave band that stays specular, the rest scattered (Lambert) as a rough
// surface's is. J. H. Rindel, "Attenuation of sound reflections due to diffraction", Nordic
// Acoustical Meeting (1986); C. L. Christensen and J. H. Rindel, "A new scattering method that
// combines roughness and diffraction effects", Forum Acusticum (2005): ODEON's reflection-based
// scattering.
//
// A plate of widths a and b, struck at angle theta, reflects of the image source's energy, in
// the paraxial Kirchhoff (Fresnel) limit for a plate well inside its first zone and Rindel's
// cut-off above,
//     K = min(1, w1^2 / (lambda L)) * min(1, w2^2 / (lambda L)),
// w1 and w2 the plate's principal widths seen from the zone (its widths in the plane of
// incidence foreshortened by cos(theta): a cos(theta) and b when a lies in that plane; in
// general from the second moment of area C of the face's flat surface about its centroid, the
// in-plane 2 x 2 block of C with its incidence row scaled by cos(theta), w^2 = 12 times its
// eigenvalues, so that w1 w2 = A cos(theta), exact for a rectangle at any orientation), and
// L = d1 d2 / (d1 + d2) (Rindel's a* = 2 L): d1 the incoming wave's radius (m: from the source
// or the ray's last diffuse reflection; a specular chain's image stays coherent), d2 the
// distance to the surface the mirrored ray strikes next, at most d1 (which receiver the ray
// will reach is not known when it turns, and a pair's result must not depend on the others
// traced in the same pass). Below Rindel's cut-off the reflection falls 6 dB per octave per
// small dimension. Where a plate fills its zone the Fresnel integral swings about 1 and K
// stays 1; where it is the zone's size K falls short of the integral's band mean by up to
// 2.4 dB per dimension (the strip's overshoot, clamped as in engine/small_reflectors.h). A
// face's moment is taken over the triangles of its flat surface facing its own way (a curved
// surface's far side and a sheet's second copy left out).
//
// A surface behind the face, parallel to it and not itself free-standing on that side (a wall
// behind a panel), within an eighth of a band's wavelength reflects with it: that band stays
// whole (as the exact paths count it, engine/small_reflectors.h).
//
// The reflection then scatters with 1 - (1 - s) K, s the material's scattering coefficient
// (ISO 17497-1). Every exact path carries the same share off such faces from its second order
// on (pathShare; at first order the Kirchhoff integral of engine/small_reflectors.h), so the
// rays it replaces and it carry alike. The face's edges (engine/diffraction.h) carry what it
// diffracts of the direct sound; the traced rays spread the rest over the room instead of
// returning it to a listener sphere whole (a sphere 0.5 m across a door leaf's reflection
// boundary, behind a thick doorway, counted its whole reflection on top of the edges' field).
// K differs between bands: a ray that carries every band goes on with one from such a face
// (engine/propagation.h).
//
// Which faces: those that stand free on the side the ray comes from (SmallReflectors::
// standsFree); a room's walls keep their reflections whole, as their image sources do.
//
// Construction: any thread; allocates O(triangles); no errors. setObjectPose: between frames.
// The rest: any thread, no allocation, no errors.
#pragma once

#include <cstdint>
#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

#include "common/bands.h"
#include "common/random.h"
#include "engine/small_reflectors.h"
#include "engine/tracer.h"
#include "scene/scene.h"

namespace dpc {

struct SurfaceBodies;  // engine/diffraction.h

class ReflectionScattering {
 public:
  /// The static mesh with its flat surfaces and candidate edges as EdgeDiffraction found them,
  /// then each object's mesh in its local frame: Geometry's triangle numbering (as
  /// SmallReflectors, which this builds and the exact paths share).
  /// rays: PropagationSettings::reflectionScattering (off: pathShare is 1, the rays are not
  /// given this object, and only the exact paths' first-order share remains).
  /// bodies: the static mesh's (EdgeDiffraction::bodies()); each object's are found here.
  ReflectionScattering(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                       const std::vector<DiffractionEdge>& edges, const SurfaceBodies& bodies,
                       const std::vector<ObjectDesc>& objects, bool rays = true);
  const SmallReflectors& reflectors() const { return reflectors_; }

  /// Object k's triangles follow `pose` (world = R local + position).
  void setObjectPose(size_t object, const Pose& pose);

  /// Whether triangle t's flat surface stands free on the side `litNormal` (unit, toward the
  /// incoming ray) faces; windingNormal is t's unit normal in its winding's sense.
  bool standsFree(uint32_t t, const glm::vec3& litNormal, const glm::vec3& windingNormal) const;

  /// The principal widths w1 >= w2 (m) of triangle t's face seen from a reflection arriving
  /// along unit `incoming` on the side of unit `litNormal` (above).
  glm::vec2 zoneWidths(uint32_t t, const glm::vec3& incoming, const glm::vec3& litNormal) const;

  /// K per octave band (above, in [0, 1]); `before` and `after` d1 and d2 (m); speedOfSound
  /// m/s. 1 in every band when L is not positive.
  Bands specularShare(uint32_t t, const glm::vec3& incoming, const glm::vec3& litNormal,
                      float before, float after, float speedOfSound) const;

  /// One reflection off triangle t at `point` (m, on or just off the surface), arriving along
  /// the unit `incoming` onto the side of unit normal `litNormal`, leaving along `mirrored` if
  /// specular; `before` = d1 (m).
  struct Reflection {
    uint32_t triangle;
    glm::vec3 point, incoming, litNormal, mirrored;
    float before;
  };
  /// K per band with d2 = `after` (m), and 1 in the bands whose eighth of a wavelength reaches
  /// a wall behind the face (backing), 1 in every band where a surface faces the point within
  /// 2 kChannelGapMax (a gap's side: its transmission is the slit's, engine/channel_path.h).
  /// Up to 2 + kBackingHits ray queries.
  Bands share(const Tracer& tracer, const Reflection& r, float after, float speedOfSound) const;
  /// K per band at the largest L reflection r can have (d2 = d1): the least it can be.
  Bands least(const Reflection& r, float speedOfSound) const {
    return specularShare(r.triangle, r.incoming, r.litNormal, r.before, r.before, speedOfSound);
  }
  /// For a ray carrying the bands `carried` (bit b: band b) with `energy` that meets reflection
  /// r: the bands it goes on with. Where the face keeps some of them whole even at its least
  /// share and not others, the ray goes on with that group or with one of the others, each
  /// carried band an equal chance (one draw of `rng`), the kept bands' energy scaled by the
  /// count carried over the count kept: unbiased per band, and the product of the scales along
  /// a path is at most kNumBands, where reweighting every band at each such face would compound.
  uint8_t narrow(const Reflection& r, float speedOfSound, uint8_t carried, Rng& rng,
                 Bands& energy) const;
  /// Whether reflection r off a free-standing face scatters in `band`, the one band the ray
  /// carries, from one uniform draw u in [0, 1): with probability 1 - (1 - s) K, s the band's
  /// scattering coefficient; d2 from one ray query along `mirrored` (only where K at the
  /// largest L, d2 = d1, is below 1). A tracing thread; no allocation.
  bool scatters(const Tracer& tracer, const Reflection& r, float speedOfSound, float s, int band,
                float u) const;
  /// The product over an exact path's reflections (triangles and points, source first, in
  /// `world`'s current pose) of the share of each one off a free-standing face: the same K
  /// as the rays traced from the source that the path replaces carry (d1 unfolded, d2 the next
  /// surface along the outgoing leg, past the listener on the last, at most d1). One ray query
  /// per such reflection, with share's.
  Bands pathShare(const Tracer& tracer, const std::vector<WorldTriangle>& world,
                  std::span<const uint32_t> triangles, std::span<const glm::vec3> points,
                  const glm::vec3& source, const glm::vec3& listener, float speedOfSound) const;

  /// A parallel surface behind the face (within kParallelCos) that does not stand free on the
  /// side toward it (a wall; a sheet's second copy and another free panel are passed through,
  /// up to kBackingHits, and so is the closed body whose face it is, its own back seen from
  /// inside) within kBackedWavelengths of a band's wavelength reflects with it. Read from free
  /// sides and bodies (welded meshes), so either winding reads alike. Behind a closed body's face the probe's first query passes the whole
  /// body (a filtered query), so a box whose back lies exactly in a wall's plane (a panel
  /// flush on it) reads as backed wherever it is struck, whichever of the two coplanar
  /// triangles a plain query would report.
  static constexpr float kBackedWavelengths = 0.125f;
  static constexpr float kParallelCos = 0.99f;
  static constexpr int kBackingHits = 4;
  /// Surfaces of up to this many triangles get a moment per triangle (its triangles facing
  /// its way); larger ones one per side.
  static constexpr size_t kMaxPerTriangle = 256;

 private:
  /// The distance (m) from reflection r's face to the wall behind it (above) along its normal,
  /// looked for up to `limit` m; infinity when none.
  float backing(const Tracer& tracer, const Reflection& r, float limit) const;

  struct Moment {
    glm::mat3 c{0.f};     ///< second moment of area over area (m^2), the mesh's frame
    int32_t object = -1;  ///< the object whose frame it is in; -1: the static mesh (world)
  };
  /// Whether triangles a and b belong to one closed body (a solid: a face's back is inside it).
  bool oneClosedBody(uint32_t a, uint32_t b) const;
  struct OtherBodies;  ///< backing's filter: passes one closed body's triangles

  SmallReflectors reflectors_;
  std::vector<uint32_t> bodyOf_;    ///< per triangle, its body (the static mesh's, then objects')
  std::vector<bool> closed_;        ///< per body, SurfaceBodies::closed
  std::vector<uint32_t> momentOf_;  ///< per triangle, its face's entry in moments_
  std::vector<Moment> moments_;
  std::vector<glm::mat3> rotation_;  ///< per object, its pose's rotation
  bool rays_ = true;                 ///< the constructor's `rays`
};

}  // namespace dpc
