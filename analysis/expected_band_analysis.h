// The analysis-side model of an exact impulse response: what the ISO 3382-1 band analysis
// (the OctaveBandPass filters of analyzeImpulseResponse in analysis/room_parameters.h) reads,
// in expectation, from an IR that carries an energy response exactly. dpc-analyze --as-measured
// and the synthesis tests compare with it.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "common/bands.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"

namespace dpc {

/// Per octave b, the expected energy of the IR through b's analysis filter in each of the
/// response's time bins. Use it to compare a simulated energy response with parameters measured
/// from real IRs, and to separate what the analysis filters do to any IR (their delay of 16 ms
/// at 63 Hz halving per octave, their skirts passing neighbouring octaves, their noise bandwidth
/// 4.7 % above the octave) from what a synthesis adds.
///
/// The model IR: a response's band value E_k is a spectral density relative to a unit
/// impulse's (synthesis/band_filters.h: a flat response is a scaled Dirac). The direct sound is
/// one zero-phase pulse at the sample nearest its delay, with amplitude spectrum
/// sqrt(sum_k M_k^2(f) E_k); every other bin j of band k is noise of density E_k[j] over M_k,
/// split into two independent half-octave processes x_kh = m_kh * (v_kh w), w unit white noise,
/// v_kh^2 = E_k[j] t_kh[j] / (samples per bin), m_kh = M_k sqrt(1 - P) and M_k sqrt(P) (M_k
/// the zero-phase power-complementary band mask of OctaveBandMasks, P = powerAbove(f, fc_k),
/// synthesis/band_filters.h; the 63 Hz mask reaches down to 0 Hz and the 8 kHz one up to
/// Nyquist), t_kh the within-band tilt (halfBandDensity, synthesis/band_tilt.h, scaled so that
/// the band keeps its energy). Its expected analysed energy is then exact: the direct pulse
/// through the filter, squared, plus sum_kh E_k t_kh (*) (h_b * m_kh)^2, convolved at the
/// response's bin resolution.
///
/// energy: bins of any width (>= 1 sample at sampleRate); direct: added when visible. Returns
/// out[b][j], same bins and unit as `energy` (1/m^2 relative to source power; divided by the analysis
/// filter's unit-impulse energy, as analyzeImpulseResponse reads a band); bins before the
/// onset (the direct sound's bin, else the response's first non-zero bin) are 0, since the
/// band analysis integrates from the broadband onset; bands whose analysis filter reaches
/// Nyquist (fc sqrt(2) >= fs/2) are all NaN. Any thread that may plan FFTW (not thread-safe:
/// not beside another thread creating plans); allocates O(bins + fs); not for the audio
/// thread. Throws std::invalid_argument when sampleRate <= 0 or the bins are shorter than a
/// sample, std::runtime_error when FFTW cannot plan.
std::array<std::vector<double>, kNumBands> expectedBandAnalysisEnergy(const EnergyResponse& energy,
                                                                      const DirectSound& direct,
                                                                      int sampleRate);

/// The onset t0 (s from emission) that the band analysis of an IR (analyzeImpulseResponse)
/// finds in a response with this direct sound: its arrival when visible (the pulse's sample,
/// ISO 3382-1 A.3.4), else NaN, for which audio::analyzeEnergyDecay takes the first non-zero
/// bin's start. Pass it with expectedBandAnalysisEnergy's bins, or the response's own with the
/// direct sound in its bin, so that C80 and D50 split where an IR's do. Any thread.
inline double onsetSecondsOf(const DirectSound& direct) {
  return direct.visible && std::isfinite(direct.delaySeconds) && direct.delaySeconds >= 0.f
             ? double(direct.delaySeconds)
             : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace dpc
