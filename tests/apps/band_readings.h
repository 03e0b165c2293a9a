// What the ISO 3382-1 band analysis (analysis/room_parameters.h) reads from an IR, band by
// band, beside what it should read: the parameters of the energy response the IR was made
// from, and those the same analysis reads from an exact IR of that response
// (analysis/expected_band_analysis.h). Shared by the synthesis fidelity tests
// (synthesis_fidelity_test, spatial_fidelity_test).
#pragma once

#include <array>
#include <vector>

#include "analysis/expected_band_analysis.h"
#include "analysis/room_parameters.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"

namespace dpc::test {

/// Strength G (dB) of a band's parameters.
inline double strengthDbOf(const audio::RoomParameters& p) {
  return audio::strengthDb(p.energy);
}

/// One band read three ways.
struct BandReading {
  int band;
  audio::RoomParameters response;  ///< the energy response's own (direct sound in its bin)
  audio::RoomParameters exactIr;   ///< the band analysis of an exact IR of the response
  audio::RoomParameters ir;        ///< the band analysis of the IR under test
};

/// An energy response and its direct sound, read per band as the response itself and as the
/// band analysis of an exact IR of it at sample rate fs; read() adds an IR's analysis.
class ResponseBands {
 public:
  ResponseBands(const EnergyResponse& er, const DirectSound& direct, int fs)
      : ResponseBands(er, direct, fs, Bands(1.f), Bands(1.f)) {}

  /// The same, the exact IR's band b read reverberantScale[b] times as high in its reverberant
  /// part and directScale[b] times in its direct sound: an exact IR whose spectrum is not flat
  /// within a band (heard through an HRIR) against the flat band model that
  /// expectedBandAnalysisEnergy reads (the model is linear in both parts).
  ResponseBands(const EnergyResponse& er, const DirectSound& direct, int fs,
                const Bands& reverberantScale, const Bands& directScale)
      : fs_(fs) {
    const auto exact = expectedBandAnalysisEnergy(er, direct, fs);
    const bool flat = reverberantScale.min() == 1.f && reverberantScale.max() == 1.f &&
                      directScale.min() == 1.f && directScale.max() == 1.f;
    const EnergyResponse none(double(er.binCount()) * er.binSeconds(), er.binSeconds());
    const auto directOnly = flat ? std::array<std::vector<double>, kNumBands>{}
                                 : expectedBandAnalysisEnergy(none, direct, fs);
    std::vector<double> e(er.binCount()), x;
    const double t0 = onsetSecondsOf(direct);  // where the IR's analysis finds the onset
    for (int b = 0; b < kNumBands; ++b) {
      for (size_t k = 0; k < e.size(); ++k) e[k] = er.bins()[k][b];
      if (direct.visible) e[size_t(direct.delaySeconds / er.binSeconds())] += direct.intensity[b];
      response_[size_t(b)] = audio::analyzeEnergyDecay(e.data(), e.size(), er.binSeconds(), t0);
      x = exact[size_t(b)];
      const double r = reverberantScale[b], d = directScale[b];
      for (size_t k = 0; k < x.size() && k < directOnly[size_t(b)].size(); ++k)
        x[k] = r * x[k] + (d - r) * directOnly[size_t(b)][k];
      exactIr_[size_t(b)] = audio::analyzeEnergyDecay(x.data(), x.size(), er.binSeconds(), t0);
    }
  }

  const audio::RoomParameters& response(int b) const { return response_[size_t(b)]; }
  const audio::RoomParameters& exactIr(int b) const { return exactIr_[size_t(b)]; }

  /// Bands firstBand .. kNumBands - 1 of `ir` (at fs) beside the response's and the exact IR's.
  std::vector<BandReading> read(const std::vector<float>& ir, int firstBand) const {
    const audio::ImpulseResponseAnalysis a =
        audio::analyzeImpulseResponse(ir.data(), ir.size(), fs_);
    std::vector<BandReading> out;
    for (int b = firstBand; b < kNumBands; ++b)
      out.push_back({b, response(b), exactIr(b), a.bands[size_t(b)]});
    return out;
  }

 private:
  int fs_;
  std::array<audio::RoomParameters, kNumBands> response_, exactIr_;
};

}  // namespace dpc::test
