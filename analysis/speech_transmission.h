// Speech transmission index (STI) of a room response from its octave-band energy envelopes, by
// the indirect method of IEC 60268-16:2020 (clause 6.2 and Annex A: the modulation transfer
// function from the squared impulse response, M. R. Schroeder, "Modulation transfer functions:
// definition and measurement", Acustica 49, 179-182, 1981):
//   m_k(F) = | sum_t e_k(t) exp(-j 2 pi F t) | / sum_t e_k(t)
// for the 7 octave bands k = 125 Hz .. 8 kHz and the 14 modulation frequencies F = 0.63 ..
// 12.5 Hz in third-octave steps; then the effective signal-to-noise ratio
// SNR = 10 log10(m / (1 - m)) clipped to [-15, 15] dB, the transmission index
// TI = (SNR + 15) / 30, the band's modulation transfer index MTI_k = mean_F TI, and
//   STI = sum_k alpha_k MTI_k - sum_k beta_k sqrt(MTI_k MTI_{k+1})
// with the standard's male-speech weights (alpha sums to 1.381, beta to 0.381, so a perfect
// channel gives exactly 1).
// No background noise, no auditory masking and no absolute speech-reception threshold: those
// need the speech and noise levels, which an energy response does not carry. The result is
// the STI of the room's reverberation alone (the "STI for a noise-free channel").
// Any thread except the audio thread; pure; allocates nothing; no errors (NaN when a band
// holds no energy).
#pragma once

#include <array>
#include <cstddef>
#include <span>

namespace dpc::audio {

/// Octave bands of the STI, 125 Hz .. 8 kHz (dpc::Bands indices 1..7).
inline constexpr int kStiBands = 7;
/// Index in dpc::Bands of the STI's first band (125 Hz).
inline constexpr int kStiFirstBand = 1;
/// Modulation frequencies, Hz (IEC 60268-16:2020: 0.63 to 12.5 Hz in third octaves).
inline constexpr int kStiModulationFrequencies = 14;
inline constexpr std::array<double, kStiModulationFrequencies> kStiModulationHz = {
    0.63, 0.8, 1.0, 1.25, 1.6, 2.0, 2.5, 3.15, 4.0, 5.0, 6.3, 8.0, 10.0, 12.5};
/// Male-speech octave weights alpha_k and redundancy factors beta_k (IEC 60268-16:2020).
inline constexpr std::array<double, kStiBands> kStiAlpha = {0.085, 0.127, 0.230, 0.233,
                                                            0.309, 0.224, 0.173};
inline constexpr std::array<double, kStiBands - 1> kStiBeta = {0.085, 0.078, 0.065,
                                                               0.011, 0.047, 0.095};

/// Modulation transfer m(F) of one band's energy envelope: energy[i] (any energy unit) in time
/// bin i = [i binSeconds, (i+1) binSeconds), taken at the bin centre. NaN when the band holds no
/// energy. Negative energies are treated as zero.
double modulationTransfer(std::span<const double> energy, double binSeconds, double hz);

/// STI of the 7 bands' energy envelopes (125 Hz .. 8 kHz, each in bins of binSeconds), 0..1;
/// NaN when any band holds no energy.
double speechTransmissionIndex(const std::array<std::span<const double>, kStiBands>& bands,
                               double binSeconds);

/// STI from a modulation transfer index per band (the weighting step alone), 0..1.
double stiFromMti(const std::array<double, kStiBands>& mti);

}  // namespace dpc::audio
