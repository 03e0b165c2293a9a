// A traced ray's reflection off a free-standing face smaller than its first Fresnel zone: the
// share of each octave band that stays specular, the rest scattered (Lambert) as a rough
// surface's is. J. H. Rindel, "Attenuation of sound reflections due to diffraction", Nordic
// Acoustical Meeting (1986); C. L. Christensen and J. H. Rindel, "A new scattering method that
// combines roughness and diffraction effects", Forum Acusticum (2005): ODEON's reflection-based
// scattering.
//
// A plate of width a in the plane of incidence and b across it, struck at angle theta, reflects
// of the image source's energy, in the paraxial Kirchhoff (Fresnel) limit for a plate well
// inside its first zone and Rindel's cut-off above,
//     K = min(1, (a cos(theta))^2 / (lambda L)) * min(1, b^2 / (lambda L)),
// L = d1 d2 / (d1 + d2), d1 the incoming wave's radius (m: from the source or the ray's last
// diffuse reflection; a specular chain's image stays coherent) and d2 the distance to the
// receiver sphere the reflected ray meets first, else to the surface it strikes next (the
// engine/propagation.h tracer's choice; Rindel's a* = 2 L): below Rindel's cut-off
// f_g = c L / (a cos)^2 the reflection falls 6 dB per octave per small dimension. Where a plate
// fills its zone the Fresnel integral swings about 1 and K stays 1; where it is the zone's size
// K falls short of the integral's band mean by up to 2.4 dB per dimension (the strip's
// overshoot, clamped as in engine/small_reflectors.h). The widths are the
// face's flat surface's, read along any in-plane direction u from its second moment of area C
// about its centroid: a_u = sqrt(12 u^T C u) (exact along a rectangle's sides).
//
// The reflection then scatters with 1 - (1 - s) K, s the material's scattering coefficient
// (ISO 17497-1): the exact paths of engine/small_reflectors.h carry what reaches a listener
// specularly at first order, the face's edges (engine/diffraction.h) what it diffracts, and the
// traced rays the rest, which a small face spreads over the room instead of returning to the
// listener sphere whole (a sphere 0.5 m across a door leaf's reflection boundary, behind a
// thick doorway, counted its whole reflection on top of the edges' field).
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
#include "engine/small_reflectors.h"
#include "engine/trace_request.h"
#include "engine/tracer.h"
#include "scene/scene.h"

namespace dpc {

class ReflectionScattering {
 public:
  /// The static mesh with its flat surfaces and candidate edges as EdgeDiffraction found them,
  /// then each object's mesh in its local frame: Geometry's triangle numbering (as
  /// SmallReflectors, which this builds and the exact paths share).
  ReflectionScattering(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                       const std::vector<DiffractionEdge>& edges,
                       const std::vector<ObjectDesc>& objects);
  const SmallReflectors& reflectors() const { return reflectors_; }

  /// Object k's triangles follow `pose` (world = R local + position).
  void setObjectPose(size_t object, const Pose& pose);

  /// Whether triangle t's flat surface stands free on the side `litNormal` (unit, toward the
  /// incoming ray) faces; windingNormal is t's unit normal in its winding's sense.
  bool standsFree(uint32_t t, const glm::vec3& litNormal, const glm::vec3& windingNormal) const;

  /// K per octave band (above, in [0, 1]) for a ray arriving along unit `incoming` at a face of
  /// triangle t with unit `litNormal`; `before` and `after` d1 and d2 (m; after may be
  /// infinite: L = before, the least K can be at any d2); speedOfSound m/s. 1 in every band
  /// when L is not positive.
  Bands specularShare(uint32_t t, const glm::vec3& incoming, const glm::vec3& litNormal,
                      float before, float after, float speedOfSound) const;

  /// One reflection off triangle t at `point` (m, just off the surface), arriving along the
  /// unit `incoming` onto the side of unit normal `litNormal`, leaving along `mirrored` if
  /// specular; `before` = d1 (m).
  struct Reflection {
    uint32_t triangle;
    glm::vec3 point, incoming, litNormal, mirrored;
    float before;
  };
  /// Whether reflection r off a free-standing face scatters, from one uniform draw u in
  /// [0, 1): with probability 1 - (1 - s) K, s the material's scattering coefficients. d2 is
  /// the distance along `mirrored` to the first of `receivers` it enters (its centre's closest
  /// approach), else to the surface `tracer` finds (one query, only where some band's K at
  /// d2 = infinity is below 1). band: the one band the ray carries, or -1 when it carries
  /// every band: then it goes specular with the bands' mean probability and `energy` is
  /// reweighted band by band (each band's probability over the mean: unbiased per band).
  /// A tracing thread; no allocation.
  bool scatters(const Tracer& tracer, std::span<const ListenerSphere> receivers,
                const Reflection& r, float speedOfSound, const Bands& s, int band, float u,
                Bands& energy) const;

  /// The specular widths a_u and a_v (m) of triangle t's flat surface along the unit in-plane
  /// directions u and v (world).
  glm::vec2 widths(uint32_t t, const glm::vec3& u, const glm::vec3& v) const;

 private:
  struct Moment {
    glm::mat3 c{0.f};     ///< second moment of area over area (m^2), the mesh's frame
    int32_t object = -1;  ///< the object whose frame it is in; -1: the static mesh (world)
  };
  SmallReflectors reflectors_;
  std::vector<Moment> moments_;      ///< per flat surface
  std::vector<glm::mat3> rotation_;  ///< per object, its pose's rotation
};

}  // namespace dpc
