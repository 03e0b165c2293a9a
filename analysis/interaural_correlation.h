// Interaural cross-correlation of a binaural impulse response (ISO 3382-1:2009 Annex B):
//   IACF(tau) = sum_{t1 <= t < t2} pL(t) pR(t + tau) / sqrt(sum pL(t)^2 sum pR(t)^2),
//   IACC = max |IACF(tau)| over |tau| <= 1 ms,
// the sums over a time window counted from the direct sound's arrival t0: early [0, 80 ms)
// (IACC_E), late [80 ms, end) (IACC_L) and all [0, end) (IACC_A). 1 for identical ears (up to
// a delay of at most 1 ms), near 0 for independent ones. Per octave band through the same
// IEC 61260-1 filters as the room parameters (analysis/room_parameters.h; both ears through
// identical filters, so their delay cancels) and broadband. Acousticians report IACC_E3 and
// IACC_L3, the means of the 500 Hz, 1 kHz and 2 kHz bands (Hidaka, Beranek & Okano, JASA 98,
// 988-1007, 1995), as measures of apparent source width and listener envelopment.
//
// t0 is the first sample of either ear within 20 dB of the louder ear's squared peak (the
// onset rule of room_parameters.h, taken over both ears). A window with no energy in either
// ear gives NaN. Threads: any thread but the audio thread; allocates O(n); no errors thrown.
#pragma once

#include <array>
#include <cstddef>

#include "common/bands.h"

namespace dpc::audio {

/// Largest interaural lag searched, seconds (ISO 3382-1 Annex B: +-1 ms).
inline constexpr double kMaxInterauralLagSeconds = 1e-3;
/// Boundary between the early and the late window, seconds after t0 (ISO 3382-1 Annex B).
inline constexpr double kInterauralEarlySeconds = 0.080;

/// IACC of one band over the three windows; each in [0, 1] or NaN.
struct InterauralCorrelation {
  double early;  ///< IACC_E: [t0, t0 + 80 ms)
  double late;   ///< IACC_L: [t0 + 80 ms, end)
  double all;    ///< IACC_A: [t0, end)
};

/// IACC per octave band (63 Hz .. 8 kHz, index as dpc::Bands; NaN above Nyquist) and broadband.
struct BinauralAnalysis {
  std::array<InterauralCorrelation, kNumBands> bands;
  InterauralCorrelation broadband;
  double onsetSeconds;  ///< t0 from the first sample; NaN when neither ear holds energy
};

/// The IACC of the ears `left` and `right`, n samples each at sampleRate Hz.
BinauralAnalysis analyzeBinaural(const float* left, const float* right, size_t n,
                                 int sampleRate);

}  // namespace dpc::audio
