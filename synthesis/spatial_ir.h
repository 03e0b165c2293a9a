// Two-channel (binaural or stereo) impulse responses from a directional energy response.
//
// K fixed directions in the listener's frame each own a Dirac sequence (independent per
// direction, so the directions add up incoherently, as a diffuse field does) that is split
// into octave bands by the amplitude-complementary filters A_b and convolved, once at
// construction, with that direction's two-channel filter (an HRIR pair, or panning gains). A
// frame then only weights those pre-convolved band signals by per-bin envelope gains
// (BandEnvelope, the same as the mono IrSynthesizer), so per frame the cost is
// K x 8 bands x 2 channels multiply-adds per sample, with no FFT. The direct sound is placed
// with the filter for its exact direction (FFT convolution of the band-shaped impulse with
// the filter). Below kDirectionalFromBand (63 and 125 Hz) the reverberant part is rendered
// once from the omnidirectional response and fed to both channels: a diffuse field is almost
// fully coherent between the ears there (sin(kd)/kd = 0.97 at 125 Hz for d = 18 cm), the
// HRTFs carry no directional cue, and K independent low-band noises would interfere with
// too few degrees of freedom to keep their band energy. All filters are diffuse-field equalised per
// band (divided by the band energy of the K directions' filters averaged over both channels), so
// that the two channels' average band energy follows the mono energy response for a diffuse field
// (taken over the analysed octave: the 63 Hz and 8 kHz bands carry their octave's spectral
// density on below 44 Hz and above 11.3 kHz, as an exact IR does). Each ear is then levelled
// on the ISO 3382-1 analysis filters (BandLeveller, synthesis/band_leveller.h) to its own target:
// sum_d E_d,b x earWeight(d, ear)[b] plus the direct sound x directWeight(ear)[b], which
// removes the slower bands' gain-step splatter from the faster ones and the expectation
// form's realisation noise over 50 ms windows.
// Method: the band-filtered Dirac sequence (Schröder 2011, section 5.3) per direction,
// rendered through HRTFs as virtual loudspeakers (e.g. Noisternig et al., "3D binaural sound
// reproduction using a virtual ambisonic approach", VECIMS 2003, for the virtual-loudspeaker
// idea).
//
// One synthesiser serves every source (its sequences are shared; sources differ by their
// envelopes). Construction: control/propagation thread (FFTW planning); allocates; throws
// std::invalid_argument on inconsistent input. synthesize(): propagation thread; does not
// allocate after the first call; no errors.
#pragma once

#include <functional>
#include <glm/vec3.hpp>
#include <memory>
#include <vector>

#include "engine/energy_response.h"
#include "common/fftw_util.h"
#include "synthesis/ir_synthesis.h"
#include "engine/propagation.h"

namespace dpc {

class BandLeveller;

/// A two-channel FIR (left, right) at the synthesis rate. Panning: one tap per channel.
struct EarFilter {
  std::vector<float> left, right;
};

class SpatialIrSynthesizer {
 public:
  /// Bands from this one up are rendered per direction; lower ones omnidirectionally.
  static constexpr int kDirectionalFromBand = 2;
  /// Per-ear levelling of the directional bands (BandLeveller): each band's analysed energy
  /// over 50 ms windows is brought to within this energy ratio of the ear's target, scaled up
  /// by at most kLevelMaxBoost (amplitude), from where each direction's Dirac sequence holds
  /// kLevelFromPulses pulses per 10 ms.
  static constexpr double kLevelTolerance = 1.0;
  static constexpr double kLevelMaxBoost = 2.0;
  static constexpr double kLevelFromPulses = 1.0;

  /// Fills a filter for an exact listener-frame direction (x forward, y left, z up).
  using ExactFilter = std::function<void(const glm::vec3& listenerDirection, EarFilter& out)>;

  /// directions: K listener-frame unit vectors; filters: one EarFilter per direction (all
  /// shorter than sampleRate / 4); exact: the filter for any direction (direct sound).
  SpatialIrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume, double speedOfSound,
                       uint64_t seed, std::vector<glm::vec3> directions,
                       const std::vector<EarFilter>& filters, ExactFilter exact);
  ~SpatialIrSynthesizer();

  size_t lengthSamples() const { return length_; }
  const std::vector<glm::vec3>& directions() const { return directions_; }
  /// Diffuse-field equalisation gain applied in band b (energy factor).
  double diffuseFieldGain(int b) const { return 1.0 / kappa_[size_t(b)]; }

  /// Direction d's filter's band energy for `ear` (0 left, 1 right; M_b^2-weighted, as a band
  /// measurement sees it) over the diffuse-field average kappa_b: what the ear's IR carries
  /// of direction d's band energy. directWeight: the same for the exact filter of the last
  /// synthesize()'s direct sound (valid when it was visible).
  const Bands& earWeight(size_t d, int ear) const { return earWeight_[d][size_t(ear)]; }
  const Bands& directWeight(int ear) const { return directWeight_[size_t(ear)]; }

  /// Writes lengthSamples() samples to left and right. energy must use this synthesiser's
  /// directions (same order); direct.direction is a world vector, rotated by energy's frame.
  void synthesize(const DirectionalEnergyResponse& energy, const DirectSound& direct, float* left,
                  float* right);

 private:
  void addDirect(const DirectSound& direct, const glm::vec3& listenerDirection, float* left,
                 float* right);

  int sampleRate_;
  size_t length_;
  std::vector<glm::vec3> directions_;
  ExactFilter exact_;
  BandFilterData filterData_;
  std::array<double, kNumBands> kappa_{};
  std::array<double, kNumBands> densityGain_{};  ///< energy factor, see the constructor
  std::vector<std::unique_ptr<BandEnvelope>> envelopes_;  ///< one per direction
  std::unique_ptr<BandEnvelope> omniEnvelope_;            ///< low bands, both channels
  std::array<std::vector<float>, kNumBands> omniBands_;   ///< omni sequence through A_b
  EnergyResponse omniEnergy_;                             ///< scratch: sum over directions
  /// bands_[k][ear][b]: the direction's sequence through A_b and its filter, length_ samples.
  std::vector<std::array<std::array<std::vector<float>, kNumBands>, 2>> bands_;
  std::array<std::vector<float>, kNumBands> bandFilter_;  ///< a_b centred at filterCentre_
  size_t filterCentre_ = 0;
  // Direct sound: FFT convolution buffers and plans, made at construction.
  size_t directFft_ = 0;
  std::unique_ptr<FftwRealTransforms> fft_;
  EarFilter exactScratch_;
  /// earWeight_[d][ear][b]: direction d's ear filter's band energy / kappa_b; directWeight_:
  /// the same for the last direct sound's exact filter.
  std::vector<std::array<Bands, 2>> earWeight_;
  std::array<Bands, 2> directWeight_{};
  std::vector<Bands> directMask2_;  ///< M_b^2 on the direct-sound FFT's bins
  std::array<double, kNumBands> directNorm_{};
  std::unique_ptr<BandLeveller> leveller_;
};

/// The K = 8 listener-frame directions dpc uses: six on the horizon every 60 degrees from
/// straight ahead, one straight up, one 40 degrees below the front (KEMAR's lowest ring).
std::vector<glm::vec3> defaultSpatialDirections();

}  // namespace dpc
