// dpc-analyze's command line as parsed, and its three modes.
#pragma once

#include <string>
#include <vector>

#include "audio/wav_io.h"

namespace dpc::analyze {

/// Every dpc-analyze option (dpc_analyze.cpp defines them with CLI11).
struct Options {
  std::string file;         ///< the IR (WAV) or energy response (.csv) to analyse
  bool json = false;        ///< JSON instead of tables
  std::string channelText;  ///< --channel N as typed (1-based; "" = all)
  std::vector<double> air;  ///< --air-attenuation T RH (empty = not asked for)
  bool asMeasured = false;  ///< energy-response CSV: what an IR's band analysis would read
  bool bandEnergy = false;  ///< band energies per time bin instead of parameters
  bool iacc = false;        ///< binaural WAV (ear pairs): IACC per band instead of parameters
  int diffusenessOrder = 0;  ///< AmbiX WAV of this order: late diffuseness (0 = not asked for)
};

/// --air-attenuation T RH: prints the ISO 9613-1 attenuation per octave band (table or JSON)
/// on stdout. Returns 0, or 1 with one line on stderr for T or RH out of range. Main thread.
int printAirAttenuation(const Options& o);

/// An energy-response CSV (dpc-demo --er-out): per source the parameters table (or JSON), or
/// with --band-energy the band energies per bin. Returns 0, or 1 with one line on stderr for
/// options that do not apply to a CSV. Main thread. Throws InputError for a bad file.
int analyzeEnergyResponse(const Options& o);

/// An impulse-response WAV: per channel (or --channel N) the parameters table (or JSON), or
/// with --band-energy the band energies per 1 ms bin. Returns 0, or 1 with one line on stderr
/// for a sample that is not finite. Main thread. Throws InputError for a bad file or channel.
int analyzeImpulseResponse(const Options& o);

/// --iacc: IACC_E, IACC_L, IACC_A per octave band, broadband and over 500 Hz - 2 kHz of the
/// binaural IR `ir` read from o.file, channels as (left, right) pairs (one per source in
/// dpc-demo --ir-out's order), a table per pair or one JSON document. Returns 0, or 1 with one
/// line on stderr when the channel count is odd. Main thread.
int analyzeInterauralCorrelation(const Options& o, const audio::AudioData& ir);

/// --diffuseness N: the late part's diffuseness (DirAC's from first order, COMEDIE's from
/// every order; analysis/ambisonic_diffuseness.h) per octave band and broadband of the AmbiX
/// IR `ir` of order N read from o.file, its channels in blocks of (N + 1)^2 (one per source in
/// dpc-demo --ir-out's order), a table per block or one JSON document. Returns 0, or 1 with
/// one line on stderr when the channel count is not a multiple of (N + 1)^2. Main thread.
int analyzeDiffuseness(const Options& o, const audio::AudioData& ir);

}  // namespace dpc::analyze
