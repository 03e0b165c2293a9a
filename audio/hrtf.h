// Hrtf: head-related impulse responses (HRIRs) per arrival direction, for binaural output.
//
// Source data: an AES69 SOFA file (AES69-2015/2020, convention SimpleFreeFieldHRIR), read with
// libmysofa (https://github.com/hoene/libmysofa, tested with Debian's 1.3.1 and the MIT KEMAR
// "normal pinna" set it ships as /usr/share/libmysofa/default.sofa: 710 directions, 512 taps at
// 44.1 kHz, elevations -40..90 degrees).
//
// Listener frame (SOFA's listener coordinates, used as is): x forward (out of the nose), y to
// the listener's left, z up; right-handed. A direction is the unit vector from the listener
// towards where the sound comes from, i.e. the reverse of the arriving ray's travel direction.
// Azimuth is counter-clockwise from +x towards +y (90 degrees = left ear), elevation up from
// the horizontal plane.
//
// Load pipeline (control thread, once): mysofa_open_no_norm(path, rate) reads and checks the
// file and resamples every HRIR to `sampleRate` (libmysofa's built-in speex resampler, quality
// 10, latency compensated, so no added delay; filter length ceil(N_file * rate / rate_file),
// delays scaled by the same ratio — verified with 1.3.1). Then a direction grid is filled
// every kGridStepDegrees in azimuth and elevation (72 x 37 nodes, poles included) straight from
// the measurements: a node on a measurement copies it; elsewhere the measurements within
// R = d + min(2 d, 10 degrees of arc) of it (d: distance to the nearest one) are blended with
// modified Shepard (inverse-distance) weights ((R - d) / (R d))^2, continuous in the direction.
// Lookups interpolate bilinearly on the grid. We do not fill the grid with libmysofa's
// mysofa_getfilter_float, because its interpolation (nearest k-d-tree measurement plus the closer
// neighbour per axis) jumps by up to 1.2 dB per 0.25 degree of azimuth and breaks KEMAR's exact
// left/right symmetry (33 % relative RMS between mirrored directions), both measured in
// tests/audio/hrtf_test.cpp; the grid's figures are 0.17 dB and 4e-6. hrirExact() keeps libmysofa's
// filter available as a reference. Directions below the file's lowest measured elevation (-40
// degrees for KEMAR) get blends of the lowest ring's measurements (no real data there).
//
// Normalisation (our choice, not libmysofa's): one gain for every filter and both ears, so
// interaural and direction-to-direction levels are those of the file, chosen so that a source
// straight ahead (direction (1, 0, 0)) has a per-ear energy of 1, i.e.
// (sum(left^2) + sum(right^2)) / 2 = 1 at the frontal direction. A frontal source therefore
// plays as loud in each ear as the mono IR. (libmysofa's own mysofa_open normalisation meant
// to do the same, but its "frontal" position is the one with the smallest azimuth + elevation,
// which for KEMAR is azimuth 0, elevation -40 degrees; we open with mysofa_open_no_norm
// instead.) Energy is counted in samples, so the level in the audible band changes by about
// 10 log10(48000 / 44100) = 0.37 dB between the two rates.
//
// Delays: AES69 Data.Delay, in samples at `sampleRate`, to be added to the HRIRs' own onset.
// For KEMAR they are all zero: the interaural time difference is inside the HRIRs.
//
// Threads: load() on the control thread (allocates ~12 MB at 48 kHz; takes ~0.5 s for KEMAR,
// mostly libmysofa's resampling and neighbour table). Afterwards the object is immutable for hrir()
// and nearestHrir(): any number of threads may call them concurrently; they are wait-free, do not
// allocate, lock or throw, so even the audio thread may use them. hrirExact() calls libmysofa,
// whose mysofa_getfilter_float writes into scratch memory owned by the MYSOFA_EASY handle
// (easy->fir in libmysofa's easy.c), so concurrent calls on one handle race; hrirExact() therefore
// serialises callers with a mutex: one thread at a time, not for the audio thread.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

namespace dpc::audio {

/// Pointers into an Hrtf's direction grid (no copy): filterLength() samples per ear, valid as
/// long as the Hrtf lives and is not moved from.
struct HrirView {
  const float* left;
  const float* right;
  float leftDelaySamples;
  float rightDelaySamples;
};

/// A SOFA HRTF set resampled to one sample rate and tabulated on a direction grid. Move-only.
class Hrtf {
 public:
  /// Debian's default SOFA file (libmysofa-data): MIT KEMAR, normal pinna.
  static constexpr const char* kDefaultSofaPath = "/usr/share/libmysofa/default.sofa";
  /// Grid spacing in azimuth and elevation, degrees.
  static constexpr float kGridStepDegrees = 5.0f;

  /// Loads the SOFA file at `path` and prepares HRIRs at `sampleRate` Hz (see the file
  /// comment for resampling, normalisation and the grid). Control thread; allocates.
  /// Throws dpc::InputError(path, "", reason) when the file is missing, unreadable, not
  /// HDF5/SOFA, or not a SimpleFreeFieldHRIR set libmysofa accepts (the reason names
  /// libmysofa's error code). Throws std::invalid_argument if sampleRate is outside
  /// [8000, 384000].
  static Hrtf load(const std::string& path, int sampleRate);

  Hrtf(Hrtf&&) noexcept;
  Hrtf& operator=(Hrtf&&) noexcept;
  ~Hrtf();

  /// Taps per ear of every HRIR returned, at sampleRate() (512 for KEMAR at 44.1 kHz, 558 at
  /// 48 kHz).
  int filterLength() const;
  /// The rate the HRIRs were resampled to, Hz.
  int sampleRate() const;

  /// HRIR pair for `direction` (listener frame, x forward, y left, z up; need not be unit
  /// length; a zero or non-finite vector is treated as straight ahead). Writes filterLength()
  /// floats to each of `left` and `right` and the delays in samples (may be fractional).
  /// Bilinear interpolation in (azimuth, elevation) between the four surrounding grid nodes;
  /// at a node that is a measurement it equals hrirExact() to float rounding. Cost: 4 x
  /// filterLength() multiply-adds per ear, measured ~1.2 us per call at 48 kHz on random
  /// directions (memory-bound: 18 KB of table per call). Any thread, concurrently; wait-free,
  /// no allocation.
  void hrir(const float direction[3], float* left, float* right, float* leftDelaySamples,
            float* rightDelaySamples) const;

  /// The grid node nearest to `direction` (same conventions as hrir()), without copying:
  /// quantises the direction by up to kGridStepDegrees / 2 in azimuth and elevation. Cheapest
  /// lookup (~50 ns), for accumulating many paths into an IR. Any thread, concurrently;
  /// wait-free.
  HrirView nearestHrir(const float direction[3]) const;

  /// The file's measurements at its largest source radius (those the grid is filled from):
  /// how many there are (710 for KEMAR).
  size_t measurementCount() const;
  /// Measurement `index` (< measurementCount(), else std::out_of_range): its unit direction
  /// (listener frame), its HRIR pair (filterLength() floats to each of left and right, with
  /// the frontal normalisation of hrir()) and its delays in samples. For decoders fitted to
  /// the measured directions themselves (audio/magls_decoder.h). Any thread; no allocation.
  void measurement(size_t index, float direction[3], float* left, float* right,
                   float* leftDelaySamples, float* rightDelaySamples) const;

  /// Reference path: libmysofa's own interpolated filter for `direction`
  /// (mysofa_getfilter_float, ~3 us per call), with our normalisation gain applied. Same outputs
  /// as hrir().
  /// Serialised by an internal mutex (libmysofa's lookup writes scratch owned by the handle):
  /// one caller at a time; not for the audio thread.
  void hrirExact(const float direction[3], float* left, float* right, float* leftDelaySamples,
                 float* rightDelaySamples) const;

 private:
  struct Impl;
  explicit Hrtf(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dpc::audio
