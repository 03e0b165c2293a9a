// dpc-demo's CLI11 definition: option names, help texts and the one-line parse errors.
#include "apps/demo/flags.h"

#include <CLI/CLI.hpp>
#include <charconv>
#include <cstdint>
#include <cstdio>

#include "apps/cli_values.h"
#include "common/input_file.h"

namespace dpc::demo {
namespace {

constexpr const char* kDescription =
    "dpc-demo: interactive sound propagation with the diffuse path cache.\n"
    "Plays SCENE.json live through PortAudio (JACK, ALSA, PulseAudio), or renders it offline\n"
    "to a WAV file (--offline), moving the listener along the scene's trajectory (or the\n"
    "keyboard with --interactive). Flags override the scene's propagation settings.";

/// A whole number that fits T (`range` says which): CLI11 itself saturates one beyond (2^64
/// would be read as 2^63 - 1 without a word), so the text is checked before it is converted.
template <class T>
CLI::Validator wholeNumber(const char* range, const char* name) {
  return CLI::Validator(
      [range](std::string& text) -> std::string {
        T v{};
        const char* end = text.data() + text.size();
        const auto r = std::from_chars(text.data(), end, v);
        if (r.ec == std::errc() && r.ptr == end) return {};
        return "'" + text + "' is not a whole number in " + range;
      },
      name);
}
const CLI::Validator kWholeInt64 = wholeNumber<int64_t>("[-2^63, 2^63)", "INT64");
/// The seed: the scene file's and dpc_scene_data's range, every uint64_t.
const CLI::Validator kWholeUint64 = wholeNumber<uint64_t>("[0, 2^64)", "UINT64");

/// dpc studio's web page (docs/studio.md), live or offline.
void addStudioOptions(CLI::App& app, Flags& fl) {
  app.add_flag("--studio", fl.studio,
               "Serve dpc studio, a web page that shows the scene and the selected pair's "
               "response and moves the listener and sources, on 127.0.0.1; prints its URL "
               "(docs/studio.md). With --offline: after the render, frames on dpc-demo's own "
               "clock until Ctrl-C");
  app.add_option("--port", fl.port, "--studio's port, 0..65535 (default 0: any free port)")
      ->check(kWholeInt64);
}

/// Scene, devices and the live run's options.
void addLiveOptions(CLI::App& app, Flags& fl) {
  app.add_option("scene", fl.scene, "Scene file (JSON; see docs/scene-format.md)");
  app.add_flag("--list-devices", fl.listDevices, "List audio output devices and exit");
  app.add_flag("--list-materials", fl.listMaterials,
               "List the materials library (names usable in a scene's materials) and exit");
  app.add_option("--device", fl.device,
                 "Output device: jack:system (JACK's playback ports; ports named ACN0.., "
                 "left/right, the layout's labels), jack:CLIENT (that client's inputs, e.g. an "
                 "Ambisonic decoder), NAME or HOSTAPI:NAME (PortAudio, e.g. alsa:hw:0,0), "
                 "portaudio:SPEC; default: JACK if a server runs, else PortAudio's default");
  app.add_option("--block-size", fl.blockSize,
                 "The engine's block in samples, in audio.block_size's range (default: live, "
                 "the JACK server's period, else the scene's audio.block_size; offline, the "
                 "scene's)");
  app.add_option("--record", fl.record, "Live: also write what was played to this WAV");
  app.add_option("--stats", fl.stats,
                 "Live: write xruns, late callbacks, callback load and motion-to-sound latency "
                 "percentiles, IRs applied and the callback's scheduling to this JSON file at "
                 "the end (docs/live.md)")
      ->type_name("FILE.json");
  app.add_option("--latency-target-ms", fl.latencyTargetMs,
                 "Live: motion-to-sound latency to stay under; frames take fewer rays when "
                 "needed (default 50; the frame period applies when it is shorter)");
  app.add_option("--ir-swap-spread-ms", fl.irSwapSpreadMs,
                 "Live: spread each IR swap over this many ms across source groups: lighter "
                 "callbacks while IRs swap, up to this much more latency (default 0: all at "
                 "once; docs/live.md)");
  app.add_option("--reconnect", fl.reconnectSeconds,
                 "Live: when the audio device fails (its JACK server stopped, the device "
                 "lost), keep tracing and reopen it every half second for up to this many "
                 "seconds (default 0: end within 2 s)")
      ->type_name("SECONDS");
  app.add_flag("--interactive", fl.interactive,
               "Live: arrows/WASD move, Q/E turn, space pauses, q quits");
  app.add_option("--listener", fl.listener,
                 "Render or play the scene's listener of this name (default: the first)");
  app.add_option("--bake", fl.bake,
                 "Play static sources from this bake of the scene (dpc-bake, HDF5): late "
                 "response interpolated between visible probes, direct sound live");
}


/// The offline render and the propagation settings it overrides.
void addRenderOptions(CLI::App& app, Flags& fl) {
  app.add_option("--offline", fl.offline, "Render offline to this WAV file (float32)");
  app.add_option("--duration", fl.duration,
                 "Seconds to render (default: longest source + IR length)");
  app.add_option("--seed", fl.seed, "Random seed (same seed: bit-identical output)")
      ->check(kWholeUint64);
  app.add_option("--rays", fl.rays, "Rays per source per frame")->check(kWholeInt64);
  app.add_option("--max-order", fl.maxOrder, "Maximum reflection order")->check(kWholeInt64);
  app.add_option("--tau", fl.tau, "Cache response time tau, seconds (0 = path tracing)");
  app.add_option("--cache-pool-mb", fl.cachePoolMb,
                 "DPC memory budget of the whole engine, MB (default: sized by the scene, 4 MB "
                 "per source-listener pair, at least 128; pairs grow their caches from it as "
                 "they need)");
  app.add_option("--cache-memory-mb", fl.cacheMb,
                 "DPC memory budget per source-listener pair, MB (default 64; beyond it, or "
                 "when the pool is spent, old entries are merged, not dropped)");
  app.add_option("--estimator", fl.estimator, "dpc | path_tracing");
  app.add_option("--tracing", fl.tracing,
                 "auto (default: from the listeners when sources outnumber them) | from_sources "
                 "| from_listeners");
  app.add_option("--dpc-weighting", fl.weighting,
                 "window (unbiased, answers within tau; default) | ema (unbiased, slower) | seed "
                 "(thesis eq. 3.2; biased high)");
  app.add_option("--threads", fl.threads, "Tracing threads (0 = all cores)")->check(kWholeInt64);
  app.add_option("--rendering", fl.rendering,
                 "auto (default: hybrid when sources outnumber the late buses) | per_source | "
                 "hybrid (early part per source, late part per cluster of sources)");
  app.add_option("--late-buses", fl.lateBuses,
                 "Hybrid rendering: late buses (source clusters) per listener, 1..64 (default 4)")
      ->check(kWholeInt64);
  app.add_option("--cluster-angle", fl.clusterAngle,
                 "Hybrid rendering: a cluster's angular radius seen from the listener, degrees "
                 "(default 30)");
}

/// The output files and their format.
void addOutputOptions(CLI::App& app, Flags& fl) {
  app.add_option("--ir-out", fl.irOut,
                 "Also write the last frame's IR (all channels) as WAV, or as SOFA (AES69 "
                 "GeneralFIR, positions included) when the name ends in .sofa");
  app.add_option("--er-out", fl.erOut,
                 "Offline: also write each source's last-frame energy response per octave band "
                 "in 1 ms bins, direct sound marked, as CSV (docs/validation.md)");
  app.add_option("--gain-db", fl.gainDb,
                 "Fixed output gain in dB (default: normalise the peak to -1 dBFS)");
  app.add_flag("--quiet", fl.quiet, "No progress bar");
  app.add_option("--output", fl.output,
                 "mono | stereo | binaural | ambisonics | ambisonic_binaural | "
                 "layout:5.1|7.1|7.1.4|FILE.json (ambisonic_binaural: AmbiX IRs of "
                 "--ambisonic-order decoded through the HRTF, turned by the head every block; "
                 "default: the scene's audio.output)");
  app.add_option("--ambisonic-order", fl.ambisonicOrder,
                 "Ambisonic output's order 1..7 (AmbiX: ACN, SN3D; (order+1)^2 channels; "
                 "default: the scene's audio.ambisonic_order, else 3)");
  app.add_flag("--max-re", fl.maxRe,
               "Ambisonic output weighted per order by max-rE (not ambisonic_binaural)");
  app.add_option("--binaural-decoder", fl.binauralDecoder,
                 "ambisonic_binaural's decoder: magls (default) | sampling (virtual "
                 "loudspeakers, for comparison; docs/spatial.md)");
  app.add_option("--hrtf", fl.hrtf,
                 "SOFA file for binaural and ambisonic_binaural output (default: "
                 "/usr/share/libmysofa/default.sofa); without --output it makes the output "
                 "binaural unless the scene's is ambisonic_binaural");
}

/// "; did you mean --NAME?" for the last unknown --option in argv that is within two edits
/// of a known option name, or "" if there is none.
std::string mistypedOptionHint(const CLI::App& app, int argc, char** argv) {
  std::string hint;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0) continue;
    const std::string name = a.substr(0, a.find('='));
    if (app.get_option_no_throw(name) != nullptr) continue;
    size_t best = 3;
    for (const CLI::Option* o : app.get_options()) {
      for (const std::string& ln : o->get_lnames()) {
        const size_t d = editDistance(name.substr(2), ln);
        if (d < best) best = d, hint = "; did you mean --" + ln + "?";
      }
    }
  }
  return hint;
}

}  // namespace

std::optional<int> parseFlags(int argc, char** argv, Flags& fl) {
  CLI::App app{kDescription};
  addLiveOptions(app, fl);
  addStudioOptions(app, fl);
  addRenderOptions(app, fl);
  addOutputOptions(app, fl);
  refuseEmptyValues(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, the same format and exit status as every other input error.
    std::string msg = e.what();
    for (char& c : msg)
      if (c == '\n' || (unsigned char)c < 0x20) c = ' ';
    std::fprintf(stderr, "dpc-demo: command line: %s%s\n", msg.c_str(),
                 mistypedOptionHint(app, argc, argv).c_str());
    return 1;
  }
  return std::nullopt;
}

}  // namespace dpc::demo
