// dpc studio's IR documents: the selected pair's pressure IR drawn in the page (a waveform
// reduced to each column's extremes, an energy envelope in dB) with its interaural
// cross-correlation when the IR is binaural (analysis/interaural_correlation.h, the code
// dpc-analyze --iacc runs), and the same IR as a float WAV for dpc-analyze. Server thread;
// allocates. Field names: docs/studio.md "API".
#pragma once

#include <string>

#include "apps/studio/studio_board.h"

namespace dpc::studio {

/// Columns of the waveform drawn: each holds the least and greatest sample of its span.
inline constexpr size_t kIrColumns = 800;
/// Bin of the energy envelope, s (the energy response's bin).
inline constexpr double kIrEnvelopeBinSeconds = 0.001;
/// Channels drawn: the first two (the ears of a binaural IR; W and Y of an AmbiX one).
inline constexpr int kIrChannelsDrawn = 2;

/// {"frame", "source", "sampleRate", "channels", "samples", "binaural", "columnSamples",
///  "min", "max" (per drawn channel, kIrColumns values), "envelopeBinSeconds", "envelopeDb"
///  (per drawn channel: 10 log10 of each bin's energy over the IR's greatest bin, null for
///  an empty bin), "iacc" (null unless binaural: "onsetSeconds", "bands" and "broadband"
///  as {"early", "late", "all"}, null for NaN), "direct" (the frame's direct sound:
///  "visible", "delaySeconds", "distance")}.
std::string irJson(const StudioIr& ir);

/// The IR as a WAV file (RIFF, IEEE float 32-bit, every channel): the same samples, bit for
/// bit, that irJson analysed.
std::string irWav(const StudioIr& ir);

}  // namespace dpc::studio
