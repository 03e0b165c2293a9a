// What a spatial synthesis's direction filters (synthesis/spatial_synthesizer.h) do to a field
// beyond their band energies: their taps' validity, the delay they give a field of noise, and
// how a levelled band's measurement sees their spectrum within and beyond its octave.
//
// A filter's share of a band is stated as one number per octave, w_b (its band energy over the
// analysed octave, diffuse-field equalised), which stands for a spectrum flat within each
// octave, sum_k w_k M_k^2 (M_k the octave masks of common/octave_band_masks.h). An HRIR is not
// flat within an octave (KEMAR's ear-canal rise), so a window levelling view M_b^2 sees noise
// through it -0.03 / -0.15 / -0.25 / +0.41 / -0.12 dB off that model at 250 Hz - 4 kHz, the
// ISO 3382-1 octave filters -0.05 / -0.21 / -0.37 / +0.62 / -0.10 dB (means over the eight
// directions and both ears; scripts/hrir_band_shape.py, independent of this code). And its
// taps delay whatever passes them: the direct sound through its exact HRIR arrives 0.7-1.8 ms
// after its path's delay, so a field whose envelope follows the response's own time axis
// would lead it by that much.
//
// longestFilter, fieldDelay, viewWeights: construction time (control or propagation thread);
// allocate; no FFTW planning (the caller's transforms are used); longestFilter throws as it
// says. delayFrom: per frame (propagation thread); no allocation, no errors.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "common/bands.h"
#include "common/fftw_util.h"
#include "common/octave_band_masks.h"

namespace dpc {

struct DirectionFilter;

/// The longest channel filter of any direction (at least 1); throws std::invalid_argument
/// unless every direction has `channels` >= 1 channels of 1 .. margin - 1 taps.
size_t longestFilter(const std::vector<DirectionFilter>& filters, size_t channels, size_t margin);

/// The delay (samples) of a field of noise through the filters: the centroid of |h|^2 (an
/// energy envelope convolved with |h|^2 moves by it), averaged over directions and channels.
size_t fieldDelay(const std::vector<DirectionFilter>& filters);

/// Delays each channel's samples from `onset` on by `delay` (length samples each; zeros
/// before onset + delay, the last `delay` samples dropped). No allocation.
void delayFrom(size_t onset, size_t delay, size_t length, std::span<float* const> channels);

/// Per direction d, channel c: the band weights u of the flat model sum_k u_k M_k^2 that puts
/// into every view M_b^2 what the view sees of white noise through the direction's filter and
/// the per-band equalisation g = sum_k M_k^2 sqrt(equalisation_k) (equalisation_k = 1 / kappa_k,
/// an energy factor), each view up to 1/6 octave above its band's upper edge (where inner masks
/// end; the 8 kHz mask's reach to Nyquist is beyond what its analysis filter measures): the
/// 8 x 8 view coupling solved for u, so that a levelled view's target counts its neighbours'
/// shapes too. One-tap filters (flat) keep `weight` exactly. masks on fft's bins, sampleRate Hz.
std::vector<std::vector<Bands>> viewWeights(const std::vector<DirectionFilter>& filters,
                                            const std::vector<std::vector<Bands>>& weight,
                                            const std::array<double, kNumBands>& equalisation,
                                            const OctaveBandMasks& masks,
                                            FftwRealTransforms& fft, int sampleRate);

}  // namespace dpc
