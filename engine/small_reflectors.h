// How much of an image source's field a small free-standing face reflects, for the exact
// specular paths (engine/specular_paths.h).
//
// The image source stands for the field an infinite plane reflects. A face reflects that field
// only where it covers the first Fresnel zone round the reflection point; a face much smaller
// than the zone reflects, by the Kirchhoff (physical-optics) integral over it with every point
// in phase, the pressure ratio
//     |p / p_image| = A cos(theta) / (lambda L),   L = a b / (a + b),
// A the face's area (m^2), theta the angle of incidence, a and b the unfolded path's lengths
// before and after the reflection point (m); the first zone's area is pi lambda L / cos(theta)
// (M. Vorländer, "Auralization", 2008, sec. 11.4.2 on reflections from finite surfaces;
// H. Kuttruff, "Room Acoustics", 5th ed., sec. 2.6). The energy factor min(1, ratio^2) per
// octave band at its centre frequency: 1 (the image source) where the face covers the zone,
// the small-face limit where it does not (between, the integral oscillates about 1 and the
// image source is kept: no band is raised). A 1 x 2.1 m door leaf 3.5 m from a source and 3 m
// from a listener, at normal incidence, reflects -12.5 dB at 63 Hz, -6.5 dB at 125 Hz, -0.5 dB
// at 250 Hz and all of it from 500 Hz up.
//
// Only faces that stand free are treated so (engine/diffraction_edges.h, freeStandingExtents:
// most of their boundary diffracts; a door leaf, a panel, a box's face): a room's wall meets
// its neighbours in concave folds, across which the image sources of the neighbouring walls
// continue its field (in a box the image sources are exact at every frequency), and stays an
// image source.
//
// Construction: any thread; allocates O(triangles); no errors. factor(): any thread; no
// allocation.
#pragma once

#include <cstdint>
#include <vector>

#include "common/bands.h"
#include "engine/coplanar_faces.h"
#include "scene/scene.h"

namespace dpc {

class SmallReflectors {
 public:
  /// meshes: the static mesh, then each object's (as CoplanarFaces numbers their triangles);
  /// faces: their coplanar faces.
  SmallReflectors(const std::vector<const Mesh*>& meshes, const CoplanarFaces& faces);

  /// The area (m^2, one side) of face f (a CoplanarFaces::faceOf value) when it stands free;
  /// 0 when it does not, or f is out of range.
  float area(uint32_t face) const { return face < area_.size() ? area_[face] : 0.f; }

  /// The energy factor per octave band (each in [0, 1]) of a reflection from face f:
  /// cosIncidence in [0, 1]; before and after, the unfolded path's lengths (m) from the source
  /// to the reflection point and from there to the listener; speedOfSound m/s. All 1 for a face
  /// that does not stand free.
  Bands factor(uint32_t face, double cosIncidence, double before, double after,
               double speedOfSound) const;

 private:
  std::vector<float> area_;  ///< per triangle number: its face's area when f stands free, else 0
};

}  // namespace dpc
