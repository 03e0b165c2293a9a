// dpc-analyze: ISO 3382-1 room acoustic parameters of an impulse-response WAV file or of an
// energy response exported by dpc-demo --er-out (a .csv file).
//
//   dpc-analyze IR.wav|ER.csv [--json] [--channel N]
//   dpc-analyze BINAURAL_IR.wav --iacc [--json]
//   dpc-analyze AMBIX_IR.wav --diffuseness ORDER [--json]
//   dpc-analyze --air-attenuation T RH [--json]
//
// Per channel (WAV) or source (CSV): T20, T30, EDT (s), C50, C80 (dB), D50 (%) and strength
// G (dB, relative to the free-field direct sound at 10 m on dpc's energy scale) in the octave
// bands 63 Hz .. 8 kHz and broadband (see analysis/room_parameters.h for the method). Control
// thread only. Bad input prints one line "FILE: FIELD: problem" on stderr and exits with status 1.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <iostream>
#include <optional>
#include <string>

#include "apps/analyze/options.h"
#include "apps/cli_values.h"
#include "common/input_error.h"

namespace dpc::analyze {
namespace {

constexpr const char* kDescription =
    "dpc-analyze: ISO 3382-1 room acoustic parameters of an impulse response.\n"
    "Reads a WAV IR, or an energy-response CSV from dpc-demo --er-out (by its .csv name).\n"
    "Prints per channel T20, T30, EDT (s), C50, C80 (dB), D50 (%) and G (dB re the free\n"
    "field at 10 m, dpc's scale: 1/(4 pi 100) relative to source power) in the octave bands\n"
    "63 Hz .. 8 kHz and broadband, from Schroeder backward integration (ISO 3382-1:2009).\n"
    "'—' (JSON: null) marks a value the IR cannot give, e.g. T30 when the decay is not\n"
    "recorded 10 dB below -35 dB, or a band above Nyquist. C50/C80 are +inf when no energy\n"
    "arrives late (JSON: the string \"+inf\"). JSON gives D50 as a ratio 0..1.\n"
    "A measured IR's stationary noise floor is found per band (Lundeby 1995) and compensated\n"
    "(ISO 3382-1:2009 5.3.3); where one is, two more rows give the impulse-response-to-noise\n"
    "ratio INR (dB) and where the integration stops (s from the onset; JSON: inr, truncation).\n"
    "Exit status: 0 on success, 1 on bad input (message on stderr).";

void addOptions(CLI::App& app, Options& o) {
  auto* irOption =
      app.add_option("IR", o.file, "Impulse response file (WAV or anything libsndfile reads)")
          ->type_name("FILE");
  app.add_option("--air-attenuation", o.air,
                 "Instead of analysing: print the ISO 9613-1 air attenuation per octave band that "
                 "dpc applies at this temperature (degrees C, -50..60) and relative humidity "
                 "(%, 0..100), as energy attenuation m (1/m) and dB/km")
      ->expected(2)
      ->type_name("T RH")
      ->excludes(irOption);
  app.add_flag("--json", o.json, "Print JSON instead of tables");
  app.add_flag("--as-measured", o.asMeasured,
               "For an energy-response CSV: the band parameters that the ISO 3382-1 band "
               "analysis of an IR carrying this response would give (expected values at 48 kHz: "
               "the octave filters' delay, skirts and noise bandwidth included), for comparison "
               "with parameters measured from real IRs");
  app.add_flag("--band-energy", o.bandEnergy,
               "Instead of parameters: print CSV rows `index,time_s,<8 bands>` under a header "
               "`channel|source,time_s,63,...,8000`: the energy "
               "per octave band in time bins (1/m^2 on dpc's scale), for plotting decay curves. "
               "WAV: channel (1 = first), 1 ms bins from the broadband onset, through the ISO "
               "analysis filters; energy-response CSV: source (0 = first), the response's own "
               "bins from emission, the direct sound in its bin (with --as-measured: what an "
               "exact IR's band analysis reads)")
      ->excludes("--json");
  app.add_flag("--iacc", o.iacc,
               "For a binaural IR (channels in left, right pairs, one per source as --ir-out writes "
               "them): instead of parameters, the "
               "interaural cross-correlation IACC (ISO 3382-1 Annex B, lags up to 1 ms) per "
               "octave band, broadband and as the 500 Hz-2 kHz mean, over the early (0-80 ms "
               "after the direct sound: IACC_E), late (80 ms on: IACC_L) and whole IR (IACC_A)")
      ->excludes("--band-energy");
  app.add_option("--diffuseness", o.diffusenessOrder,
                 "For an AmbiX IR of this order (1-7; ACN, SN3D; channels in blocks of (N+1)^2, "
                 "one per source as --ir-out writes them): instead of parameters, the late "
                 "part's (80 ms after the direct sound on) diffuseness per octave band and "
                 "broadband, 0 for one plane wave and 1 for a diffuse field: DirAC's from the "
                 "first-order channels and COMEDIE's from every order's covariance")
      ->type_name("ORDER")
      ->check(CLI::Range(1, 7))
      ->excludes("--band-energy")
      ->excludes("--iacc");
  app.add_option("--channel", o.channelText, "Analyse only channel N (1 = first; default: all)")
      ->type_name("N")
      ->excludes("--iacc")
      ->excludes("--diffuseness");
}

/// Parses argv into `o`; the exit status when the program must stop (help, parse error).
std::optional<int> parseOptions(int argc, char** argv, Options& o) {
  CLI::App app{kDescription, "dpc-analyze"};
  addOptions(app, o);
  refuseEmptyValues(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "dpc-analyze: " << e.what() << " (see --help)\n";
    return 1;
  }
  return std::nullopt;
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() &&
         std::equal(tail.rbegin(), tail.rend(), s.rbegin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) ==
                  std::tolower(static_cast<unsigned char>(b));
         });
}

/// Analyses the file by its kind: an energy-response CSV by its name, a WAV otherwise.
int analyzeFile(const Options& o) {
  const bool csv = endsWith(o.file, ".csv");
  if (o.iacc && csv) {
    std::cerr << "dpc-analyze: --iacc: " << o.file
              << ": needs a binaural impulse-response WAV (an energy response has no ears)\n";
    return 1;
  }
  if (o.diffusenessOrder > 0 && csv) {
    std::cerr << "dpc-analyze: --diffuseness: " << o.file
              << ": needs an AmbiX impulse-response WAV (an energy response has no channels)\n";
    return 1;
  }
  if (o.asMeasured && !csv) {
    std::cerr << "dpc-analyze: --as-measured: " << o.file
              << ": needs an energy-response CSV from dpc-demo --er-out (an IR is already "
                 "measured)\n";
    return 1;
  }
  return csv ? analyzeEnergyResponse(o) : analyzeImpulseResponse(o);
}

}  // namespace
}  // namespace dpc::analyze

int main(int argc, char** argv) {
  dpc::analyze::Options o;
  if (const auto status = dpc::analyze::parseOptions(argc, argv, o)) return *status;
  if (!o.air.empty()) return dpc::analyze::printAirAttenuation(o);
  if (o.file.empty()) {
    std::cerr << "dpc-analyze: IR: an impulse response file is required (see --help)\n";
    return 1;
  }
  try {
    return dpc::analyze::analyzeFile(o);
  } catch (const dpc::InputError& e) {
    std::cerr << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << o.file << ": " << e.what() << "\n";
    return 1;
  }
}
