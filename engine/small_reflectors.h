// How much of an image source's field a face reflects when it is smaller than its first
// Fresnel zone and stands free, for the exact specular paths (engine/specular_paths.h).
//
// The image source stands for the field an infinite plane reflects. By the Kirchhoff
// (physical-optics) integral in its paraxial (Fresnel) form, a plane reflects it from round the
// reflection point, each point of the plane with the phase pi s, s = rho^2 its zone number
// squared: rho = 1 on the first Fresnel zone's rim, an ellipse of semi-axes
// sqrt(lambda L) / cos(theta) in the plane of incidence and sqrt(lambda L) across it,
// L = a b / (a + b), a and b the unfolded path's lengths before and after the reflection point
// (m), theta the angle of incidence. Over the part of the plane that coplanar surface covers,
//     p / p_image = (pi / Z) * integral of e^{-j pi s} dA,    Z the first zone's area:
// 1 for the whole plane, A cos(theta) / (lambda L) for a plate of area A well inside the first
// zone, 1/2 for a half-plane whose edge passes through the point, a Fresnel integral for a strip.
// The integral is taken over the first kTaperEnd zones, its weight tapered from the first
// zone's rim on (taper(): over one and a half periods of the phase, so that the whole plane
// gives exactly 1). The energy share per octave band is min(1, |p / p_image|^2), |p / p_image|^2
// the mean over kBandPoints frequencies across the band: no band is raised (round a plate the size
// of the first zone the integral swings about 1). H. Kuttruff, "Room Acoustics", 5th ed. (2009), on
// reflections from finite surfaces and Fresnel zones; J. H. Rindel, "Attenuation of sound
// reflections due to diffraction", Nordic Acoustical Meeting (1986), the method behind ODEON's
// reflection-based scattering.
//
// The covered part counts every coplanar surface, whatever its body: a row of tables at one
// height or a wall's panels reflect together. The reflecting surface's own part, its flat
// surface (engine/diffraction_edges.h flatSurfaces) less its triangles facing the other way (a
// double-sided sheet's second copy, a curved surface's far side), is integrated over its
// triangles, the phase taken linear over each piece and integrated exactly, a piece halved
// while it departs from linear by more than 0.3 rad (at most 1,024 triangles; one piece each
// up to 16,384; beyond, the probes find it). Other surface is found by kZoneSamples probes
// spread evenly over the tapered ellipse (a sunflower pattern), a ray across the plane at each from
// an eighth of a wavelength before it to as far behind: a parallel surface that near counts too (a
// panel on a wall and the wall round it reflect together at low frequencies), its phase shifted by
// the path it saves or adds; one farther off does not (a hard limit: a panel 0.3 m before a wall
// reads it at 63-125 Hz only).
//
// First-order paths only. There the face's edges diffract the direct sound (engine/
// diffraction.h) and carry the rest of its field, the lobe round the image that a small face
// spreads wide: the edges' reflection-boundary terms are left out only where the face holds the
// reflection point, where their coherent sum with the reflection is the integral above. At
// higher orders no edge diffracts the reflected sound: there a path carries the traced rays'
// Rindel share, whose rest the rays scatter (engine/reflection_scattering.h; docs/validation.md,
// "Reflections off faces smaller than a Fresnel zone").
//
// Which faces: those that stand free on the side the sound comes from, three quarters of their
// boundary (kFreeStanding, engine/diffraction_edges.h) convex from that side: a free rim, or a
// wedge whose air side is wider than pi (a door leaf, a panel, a box's face, a thick doorway's
// reveal). A room's wall meets its neighbours in concave folds, across which the neighbouring
// walls' image sources continue its field (in a box the image sources are exact at every
// frequency), and keeps its image source; so does a leaf's side that makes a corner with the
// wall at its hinge. The side is taken from the reflection itself, so a mesh wound either way
// is read alike.
//
// Construction: any thread; allocates O(triangles); no errors. firstOrderShare(): the
// propagation thread (the Tracer's queries); no allocation; no errors.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"
#include "engine/tracer.h"
#include "scene/scene.h"

namespace dpc {

struct DiffractionEdge;  // engine/diffraction.h (which includes this header through propagation.h)

/// A triangle in world coordinates (m), its corners in winding order.
struct WorldTriangle {
  glm::vec3 v0{0.f}, v1{0.f}, v2{0.f};
};

class SmallReflectors {
 public:
  /// Points probed per band over the tapered ellipse for other coplanar surface.
  static constexpr int kZoneSamples = 64;
  /// Frequencies per octave band at which the integral is taken, log-spaced across the band
  /// (the band's energy is their mean).
  static constexpr int kBandPoints = 4;
  /// The integral's weight is 1 out to zone number squared kTaperStart, 0 from kTaperEnd.
  static constexpr double kTaperStart = 1.0, kTaperEnd = 4.0;
  /// The integral's weight at zone number squared s: cos^2 from kTaperStart to kTaperEnd.
  static double taper(double s);
  /// The least cos(theta) taken: at grazing incidence the zone runs 20 radii along the plane.
  static constexpr double kGrazingCos = 0.05;

  /// The static mesh with its flat surfaces and candidate edges as EdgeDiffraction found them
  /// (EdgeDiffraction::surfaces() and edges()), then each object's mesh in its local frame
  /// (convexity does not change under a rigid motion): Geometry's triangle numbering.
  SmallReflectors(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                  const std::vector<DiffractionEdge>& edges,
                  const std::vector<ObjectDesc>& objects);

  /// Whether triangle t's flat surface stands free on its front side (the side its winding's
  /// normal points to) when `front`, else on its back side. False for t out of range.
  bool standsFree(uint32_t t, bool front) const;
  /// Flat surfaces (the static mesh's, then each object's) and triangle t's; t < the
  /// triangle count.
  size_t surfaceCount() const { return members_.size(); }
  uint32_t surfaceOf(uint32_t t) const { return surface_[t]; }
  const std::vector<uint32_t>& trianglesOf(uint32_t surface) const { return members_[surface]; }

  /// The share per octave band that a first-order path from `source` (m) reflected at `point`
  /// (m) off triangle t (Geometry's number, in `world`: every triangle in its current pose)
  /// reflects, `length` the path's unfolded length (m), speedOfSound m/s. 1 in every band off a
  /// face that does not stand free. Higher orders: ReflectionScattering::pathShare.
  Bands firstOrderShare(const Tracer& tracer, const std::vector<WorldTriangle>& world, uint32_t t,
                        const glm::vec3& point, const glm::vec3& source, double length,
                        double speedOfSound) const;

  /// One reflection's first Fresnel zone: the point (m), the unit normal toward the incoming
  /// sound, unit in-plane axes u (in the plane of incidence) and v, cos(theta) (at least
  /// kGrazingCos) and L (m).
  struct Zone {
    glm::dvec3 point, normal, u, v;
    double cosIncidence, distance;
  };
  /// The zone of a reflection at `point` on a face of unit normal `litNormal` (toward the
  /// incoming sound), arriving along the unit `incoming`, `before` and `after` the unfolded
  /// lengths (m, > 0) to and from it.
  static Zone zoneOf(const glm::dvec3& point, const glm::dvec3& litNormal,
                     const glm::dvec3& incoming, double before, double after);
  /// The energy share per octave band of a reflection in `zone` off the flat surface of
  /// triangle t (Geometry's number).
  Bands share(const Tracer& tracer, const std::vector<WorldTriangle>& world, uint32_t t,
              const Zone& zone, double speedOfSound) const;

 private:
  /// |p / p_image|^2 averaged over the band's kBandPoints frequencies for a reflection off
  /// triangle t's flat surface, its centre's zone of semi-axes radius / cosIncidence and radius
  /// (m), its centre's wavelength (m): of all the surface counted (total: other coplanar and
  /// parallel surface within an eighth of the wavelength too) and of the part that counts at
  /// every band (lasting: the face's own flat surface and other surface within `lasting` m of
  /// its plane).
  struct Ratio {
    double total, lasting;
  };
  Ratio energyRatio(const Tracer& tracer, const std::vector<WorldTriangle>& world, uint32_t t,
                    const Zone& zone, double radius, double wavelength, double lasting) const;

  std::vector<uint8_t> free_;      ///< per triangle: bit 0 its front stands free, bit 1 its back
  std::vector<uint32_t> surface_;  ///< per triangle, its flat surface (objects' after the mesh's)
  std::vector<std::vector<uint32_t>> members_;      ///< per flat surface, its triangles
  std::array<glm::dvec2, kZoneSamples> samples_{};  ///< in the unit disk
};

}  // namespace dpc
