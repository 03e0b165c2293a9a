// Vector base amplitude panning (VBAP) over an arbitrary loudspeaker layout.
//
// V. Pulkki, "Virtual sound source positioning using vector base amplitude panning", JAES
// 45(6), 456-466 (1997): a direction p between the loudspeakers l1, l2 (2-D) or l1, l2, l3
// (3-D) of one pair or triangle gets the gains g = p^T L^-1 (L's rows the loudspeakers' unit
// vectors), all >= 0 inside it, normalised to sum g^2 = 1 (constant power). A layout whose
// loudspeakers all lie on the horizon is 2-D: adjacent pairs in azimuth, and a direction's
// horizontal projection is panned (straight up or down: every loudspeaker at 1/sqrt(L)).
// Otherwise 3-D: the triangles are the faces of the loudspeakers' convex hull; a layout with
// none below -45 degrees (or above +45) gets an imaginary loudspeaker at the nadir (zenith)
// that closes the hull, whose gain is dropped and the rest renormalised to sum g^2 = 1 (the
// imaginary loudspeakers of AllRAD, Zotter & Frank, "All-round ambisonic panning and
// decoding", JAES 60(10), 2012). Four coplanar loudspeakers (7.1.4's rear four) make one
// face of the hull, which either diagonal would split unevenly (a source straight behind
// leaning to one side): there the gains are the mean of both splits' VBAP gains, which still
// point at the direction (each does) and keep a symmetric layout's panning symmetric.
//
// Listener frame as in audio/hrtf.h: x forward, y left, z up; azimuth counter-clockwise
// (positive to the left), elevation up. Construction: control thread, allocates, throws
// std::invalid_argument for fewer than two loudspeakers or two within 1 degree of each other.
// gains(): any thread, no allocation.
#pragma once

#include <array>
#include <span>
#include <vector>

namespace dpc::audio {

class Vbap {
 public:
  /// Loudspeaker directions (azimuth, elevation) in degrees.
  Vbap(std::span<const std::array<double, 2>> directionsDegrees);

  size_t speakerCount() const { return speakers_.size(); }
  /// Constant-power gains (sum g^2 = 1) of `dir` (need not be unit length; zero: straight
  /// ahead) into out[0 .. speakerCount() - 1].
  void gains(const float dir[3], std::span<float> out) const;
  /// The hull's triangles (3-D) or pairs (2-D, third index unused), indices into the
  /// loudspeakers followed by the imaginary ones.
  const std::vector<std::array<int, 3>>& faces() const { return faces_; }

 private:
  using Vec = std::array<double, 3>;
  void buildPairs();
  void buildHull();
  /// Equal power over the real loudspeakers around the imaginary one of `face`.
  void shareImaginary(const std::array<int, 3>& face, std::span<float> out) const;
  /// Gains of p for face f; false if p lies outside it.
  bool faceGains(size_t f, const Vec& p, std::array<double, 3>& g) const;
  /// For each pair of faces that share an edge and lie in one plane (a face of four), the
  /// two triangles of its other diagonal, appended to faces_ after the hull's.
  void addOtherDiagonals();
  /// Adds to out the gains of p in the other diagonal's triangle of face f's face of four.
  void addOtherSplit(size_t f, const Vec& p, std::span<float> out) const;

  std::vector<Vec> speakers_;  ///< unit vectors, then the imaginary ones
  size_t real_ = 0;
  bool planar_ = false;
  std::vector<std::array<int, 3>> faces_;
  std::vector<std::array<double, 9>> inverses_;  ///< L^-1 per face, row-major
  size_t hullFaces_ = 0;         ///< faces_[0, hullFaces_): the hull's; then other diagonals' pairs
  std::vector<int> otherSplit_;  ///< per hull face: its other diagonal's first triangle, or -1
};

}  // namespace dpc::audio
