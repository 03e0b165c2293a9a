// dpc-demo: render a scene through the diffuse path cache, offline to a WAV file (live
// playback builds on the same pipeline).
#include <poll.h>
#include <sys/resource.h>
#include <termios.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <glm/geometric.hpp>
#include <numbers>
#include <string>
#include <thread>

#include "audio/audio_device.h"
#include "audio/wav_io.h"
#include "analysis/energy_response_csv.h"
#include "common/input_error.h"
#include "common/input_file.h"
#include "common/output_file.h"
#include "scene/scene.h"
#include "engine/setup_check.h"
#include "engine/workload.h"
#include "runtime/live_session.h"
#include "runtime/offline_renderer.h"

using namespace dpc;

namespace {

struct Flags {
  std::string scene, offline, irOut, erOut, estimator, weighting, device, record, stats, output,
      hrtf, listener;
  int64_t blockSize = 0;
  bool listDevices = false, interactive = false, hasBlockSize = false;
  double duration = 0.0, tau = 0.0, gainDb = 0.0, cacheMb = 64.0, latencyTargetMs = 50.0;
  int64_t seed = 0, rays = 0, maxOrder = 0, threads = 0;
  bool quiet = false;
  // Which options the user gave (so that any value, even a sentinel-looking one, is checked).
  bool hasDuration = false, hasTau = false, hasCacheMb = false, hasGain = false, hasSeed = false,
       hasRays = false, hasMaxOrder = false, hasThreads = false;
};

/// Longest render accepted, seconds (a day).
constexpr double kMaxDurationSeconds = 86400.0;

void progressBar(double done, double total) {
  const int width = 40;
  const double f = total > 0 ? std::min(1.0, done / total) : 1.0;
  const int filled = int(f * width);
  if (isatty(STDERR_FILENO)) {
    std::fprintf(stderr, "\r[%.*s%*s] %3d%%  %.1f / %.1f s", filled,
                 "########################################", width - filled, "", int(f * 100), done,
                 total);
    if (f >= 1.0) std::fprintf(stderr, "\n");
  } else if (int(f * 100) % 10 == 0) {
    std::fprintf(stderr, "progress %3d%%  %.1f / %.1f s\n", int(f * 100), done, total);
  }
}

PropagationSettings applyOverrides(const SceneDesc& scene, const Flags& fl) {
  PropagationSettings s = scene.propagation;
  auto bad = [&](const char* flag, const std::string& why) {
    throw InputError("command line", flag, why);
  };
  if (fl.hasSeed) {
    if (fl.seed < 0) bad("--seed", "must be >= 0");
    s.seed = uint64_t(fl.seed);
  }
  if (fl.hasRays) {
    if (fl.rays < 1 || fl.rays > 100'000'000) bad("--rays", "must be in 1..100000000");
    s.raysPerFrame = int(fl.rays);
  }
  if (fl.hasMaxOrder) {
    if (fl.maxOrder < 0 || fl.maxOrder > 10'000) bad("--max-order", "must be in 0..10000");
    s.maxOrder = int(fl.maxOrder);
  }
  if (fl.hasTau) {
    if (!(fl.tau >= 0.0 && fl.tau <= 3600.0)) bad("--tau", "must be in [0, 3600] seconds");
    s.cacheTau = float(fl.tau);
  }
  if (fl.hasCacheMb) {
    if (!(fl.cacheMb > 0.0 && fl.cacheMb <= 16384.0))
      bad("--cache-memory-mb", "must be in (0, 16384] megabytes");
    s.cacheMemoryMb = float(fl.cacheMb);
  }
  if (fl.hasThreads) {
    if (fl.threads < 0 || fl.threads > 1024) bad("--threads", "must be in 0..1024");
    s.threads = int(fl.threads);
  }
  if (!fl.estimator.empty()) {
    auto e = parseEstimator(fl.estimator);
    if (!e) bad("--estimator", "'" + fl.estimator + "' is not dpc or path_tracing");
    s.estimator = *e;
  }
  if (!fl.weighting.empty()) {
    auto w = parseDpcWeighting(fl.weighting);
    if (!w) bad("--dpc-weighting", "'" + fl.weighting + "' is not ema, seed or window");
    s.dpcWeighting = *w;
  }
  return s;
}

/// --output / --hrtf: the scene's audio output settings, overridden.
void applyAudioOverrides(SceneDesc& scene, const Flags& fl) {
  if (!fl.output.empty()) {
    auto o = parseOutputFormat(fl.output);
    if (!o)
      throw InputError("command line", "--output",
                       "'" + fl.output + "' is not mono, stereo or binaural");
    scene.audio.output = *o;
  }
  if (!fl.hrtf.empty()) {
    if (!std::filesystem::is_regular_file(fl.hrtf))
      throw InputError("command line", "--hrtf", "file '" + fl.hrtf + "' not found");
    scene.audio.hrtfPath = fl.hrtf;
    if (fl.output.empty()) scene.audio.output = OutputFormat::kBinaural;
  }
  if (!fl.listener.empty()) listenerIndex(scene, fl.listener, "--listener");  // known name?
}

/// --listener: the listener played or rendered (scene.listeners index); the first without it.
size_t selectedListener(const SceneDesc& scene, const Flags& fl) {
  return fl.listener.empty() ? 0 : listenerIndex(scene, fl.listener, "--listener");
}

/// OUT.wav -> OUT-NAME.wav (the listener's name before the extension).
std::string withListener(const std::string& path, const std::string& name) {
  if (path.empty()) return path;
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return path + "-" + name;
  return path.substr(0, dot) + "-" + name + path.substr(dot);
}

/// The files one offline render writes for one listener (empty = not asked for).
struct OutputPaths {
  std::string audio, ir, energy;
};

/// Offline without --listener renders every listener: one listener writes the names as given,
/// several write OUT-NAME.wav (and IR-NAME.wav, ER-NAME.csv) each.
std::vector<OutputPaths> offlineOutputs(const SceneDesc& scene, const Flags& fl) {
  if (!fl.listener.empty() || scene.listeners.size() <= 1)
    return {{fl.offline, fl.irOut, fl.erOut}};
  std::vector<OutputPaths> v;
  for (const ListenerDesc& l : scene.listeners)
    v.push_back({withListener(fl.offline, l.name), withListener(fl.irOut, l.name),
                 withListener(fl.erOut, l.name)});
  return v;
}

/// Refuses, before any work, an output path that names an input (scene, meshes, dry signal,
/// SOFA: same device and inode, symlinks followed), an existing non-regular file, another output,
/// or a folder that does not exist. writeWav then replaces the file only on success.
/// A scene whose sources have no signal is for hosts that feed them (C API, LV2 plugin);
/// dpc-demo would only render silence.
void requireSignal(const SceneDesc& scene) {
  for (const SourceDesc& s : scene.sources)
    if (!s.signalPath.empty()) return;
  throw InputError(scene.path, "sources[0].signal",
                   "no source has a signal: nothing to play (signal-less scenes are for the C "
                   "API and the LV2 plugin, which feed the sources)");
}

void checkOutputs(const SceneDesc& scene, const Flags& fl) {
  std::vector<std::pair<std::string, std::string>> inputs = {{fl.scene, "the scene file"},
                                                             {scene.meshPath, "the mesh"}};
  for (const auto& obj : scene.objects) inputs.push_back({obj.meshPath, "an object's mesh"});
  for (const auto& src : scene.sources) inputs.push_back({src.signalPath, "a dry signal"});
  if (!scene.audio.hrtfPath.empty()) inputs.push_back({scene.audio.hrtfPath, "the SOFA file"});
  std::vector<std::pair<const char*, std::string>> outputs = {{"--record", fl.record},
                                                              {"--stats", fl.stats}};
  if (!fl.offline.empty())
    for (const OutputPaths& o : offlineOutputs(scene, fl)) {
      outputs.push_back({"--offline", o.audio});
      outputs.push_back({"--ir-out", o.ir});
      outputs.push_back({"--er-out", o.energy});
    }
  for (size_t i = 0; i < outputs.size(); ++i) {
    const auto& [flag, out] = outputs[i];
    if (out.empty()) continue;
    struct stat st {};
    if (::stat(out.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      throw InputError("command line", flag, "'" + out + "' exists and is not a regular file");
    for (const auto& [in, what] : inputs)
      if (sameFile(out, in))
        throw InputError("command line", flag,
                         "'" + out + "' is " + what + "; refusing to overwrite it");
    for (size_t j = 0; j < outputs.size(); ++j) {
      const auto& [flag2, out2] = outputs[j];
      if (j != i && !out2.empty() &&
          (sameFile(out, out2) ||
           std::filesystem::weakly_canonical(std::filesystem::absolute(out)) ==
               std::filesystem::weakly_canonical(std::filesystem::absolute(out2))))
        throw InputError("command line", flag, "'" + out + "' is also written for " + flag2);
    }
    std::filesystem::path folder = std::filesystem::path(out).parent_path();
    if (folder.empty()) folder = ".";
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec))
      throw InputError("command line", flag, "folder '" + folder.string() + "' does not exist");
    if (::access(folder.c_str(), W_OK) != 0)
      throw InputError("command line", flag, "folder '" + folder.string() + "' is not writable");
  }
}

void writeListener(const Flags& fl, const SceneDesc& scene, const OfflineListenerResult& r,
                   audio::WavStreamWriter& writer, const OutputPaths& paths);
void printTotals(const OfflineResult& r, double audioSeconds);

/// Memory a render may plan to use for its impulse responses: half of the smaller of the
/// machine's physical memory and the process's address-space and data limits (the other half
/// is for tracing, the cache, signals and the libraries).
double memoryLimitBytes() {
  double limit = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
  for (const int which : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit rl{};
    if (getrlimit(which, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
      limit = std::min(limit, double(rl.rlim_cur));
  }
  return 0.5 * limit;
}

/// Refuses a render that cannot finish or fit (engine/workload.h) and prints one-line warnings
/// for heavy work and for setups that cannot be meant (engine/setup_check.h). Before any work.
/// durationSeconds <= 0: not known yet (before the dry signals are loaded; live), only the
/// per-frame and memory checks apply and nothing is printed; call again once it is known.
void checkSetup(const SceneDesc& scene, const PropagationSettings& settings, double durationSeconds,
                bool warn) {
  const WorkloadEstimate e =
      estimateWorkload(scene, settings, outputChannels(scene.audio.output), durationSeconds);
  const std::vector<std::string> heavy = checkWorkload(scene, settings, e, memoryLimitBytes());
  if (!warn) return;
  for (const std::string& w : heavy) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const std::string& w : setupWarnings(scene))
    std::fprintf(stderr, "warning: %s\n", w.c_str());
}

int runOffline(const Flags& fl) {
  const auto shared = std::make_shared<SceneDesc>(loadScene(fl.scene));
  SceneDesc& scene = *shared;
  applyAudioOverrides(scene, fl);
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const PropagationSettings settings = applyOverrides(scene, fl);
  if (fl.hasDuration && !(fl.duration > 0.0 && fl.duration <= kMaxDurationSeconds))
    throw InputError("command line", "--duration",
                     "must be in (0, " + std::to_string(int(kMaxDurationSeconds)) + "] seconds");
  if (fl.hasGain && !(fl.gainDb >= -120.0 && fl.gainDb <= 60.0))
    throw InputError("command line", "--gain-db", "must be a number in [-120, 60] dB");
  checkOutputs(scene, fl);
  requireSignal(scene);
  // Work and memory first (loading many or long signals takes time), then with the length.
  checkSetup(scene, settings, fl.hasDuration ? fl.duration : 0.0, false);
  const auto dry = std::make_shared<const DrySignals>(loadDrySignals(scene));
  for (const std::string& n : dry->notes) std::fprintf(stderr, "note: %s\n", n.c_str());
  OfflineOptions lengthOnly;
  lengthOnly.durationSeconds = fl.hasDuration ? fl.duration : -1.0;
  lengthOnly.listener = selectedListener(scene, fl);
  checkSetup(scene, settings, offlineDurationSeconds(scene, settings, *dry, lengthOnly), true);
  const std::vector<OutputPaths> paths = offlineOutputs(scene, fl);
  // Several listeners: one propagation run traces them all (one pass per source and frame).
  OfflineOptions opt;
  opt.durationSeconds = fl.hasDuration ? fl.duration : -1.0;
  opt.allListeners = paths.size() > 1;
  opt.listener = selectedListener(scene, fl);
  if (!fl.quiet) opt.progress = progressBar;
  // Each listener streams to a temporary file next to its output (memory independent of the
  // duration), renamed into place only once complete; a failed render leaves no file.
  // --gain-db is applied as the blocks are written.
  std::vector<std::unique_ptr<audio::WavStreamWriter>> writers;
  for (const OutputPaths& p : paths)
    writers.push_back(std::make_unique<audio::WavStreamWriter>(
        p.audio, scene.audio.sampleRate, outputChannels(scene.audio.output),
        audio::SampleFormat::kFloat32));
  const float fixedGain = fl.hasGain ? float(std::pow(10.0, fl.gainDb / 20.0)) : 1.f;
  opt.sink = [&](size_t l, const float* const* planar, size_t frames) {
    writers.at(l)->write(planar, frames, fixedGain);
  };
  const OfflineResult r = renderOffline(shared, settings, dry, opt);
  const double audioSeconds = double(writers.front()->frames()) / scene.audio.sampleRate;
  for (size_t l = 0; l < r.listeners.size() && l < paths.size(); ++l)
    writeListener(fl, scene, r.listeners[l], *writers[l], paths[l]);
  printTotals(r, audioSeconds);
  return 0;
}

/// Finishes one listener's render streamed into `writer` (level: peak normalised to -1 dBFS
/// by a second streaming pass, or --gain-db already applied), renames it into place and writes
/// its --ir-out / --er-out files.
void writeListener(const Flags& fl, const SceneDesc& scene, const OfflineListenerResult& r,
                   audio::WavStreamWriter& writer, const OutputPaths& paths) {
  const float peak = writer.peak();
  if (peak == 0.f)
    std::fprintf(stderr,
                 "warning: %s: the render of listener \"%s\" is silent (empty energy response: "
                 "is the listener inside the mesh and each source inside the room?)\n",
                 fl.scene.c_str(), r.name.c_str());
  double gainDb = fl.gainDb;
  if (!fl.hasGain) {
    gainDb = peak > 0.f ? -1.0 - 20.0 * std::log10(peak) : 0.0;
    writer.rescale(float(std::pow(10.0, gainDb / 20.0)));
  }
  const size_t frames = writer.frames();
  writer.commit();
  if (!paths.ir.empty()) {
    audio::AudioData ir;
    ir.sampleRate = scene.audio.sampleRate;
    for (const auto& source : r.lastIrs)
      for (const auto& channel : source) ir.channels.push_back(channel);
    audio::writeWav(paths.ir, ir, audio::SampleFormat::kFloat32);
  }
  if (!paths.energy.empty()) {
    std::vector<SourceEnergy> er;
    for (size_t s = 0; s < r.lastEnergy.size(); ++s)
      er.push_back({r.lastEnergy[s], r.lastDirect[s]});
    writeEnergyCsv(paths.energy, er);
  }
  const double audioSeconds = double(frames) / scene.audio.sampleRate;
  const char* format = scene.audio.output == OutputFormat::kBinaural ? "binaural"
                       : scene.audio.output == OutputFormat::kStereo ? "stereo"
                                                                     : "mono";
  std::printf("wrote %s (%.2f s, %d Hz, %s, float32, gain %+.1f dB)\n", paths.audio.c_str(),
              audioSeconds, scene.audio.sampleRate, format, gainDb);
  if (!paths.energy.empty())
    std::printf("wrote %s (last frame's energy response, %zu source(s))\n", paths.energy.c_str(),
                r.lastEnergy.size());
  if (!paths.ir.empty())
    std::printf("wrote %s (last frame's IR, %zu channel(s): source-major)\n", paths.ir.c_str(),
                r.lastIrs.size() * r.lastIrs.front().size());
}

/// One line per propagation run (shared by every listener it rendered).
void printTotals(const OfflineResult& r, double audioSeconds) {
  const auto& t = r.totals;
  std::printf(
      "frames %llu  IRs applied %llu  rays/s %.3g  segments/s %.3g  cache entries %zu (%.1f MB)\n"
      "cache budget %.1f MB  coarse entries %zu  entries merged %llu (carrying %.2f %% of the "
      "response's energy)\n"
      "propagation %.2f s (trace %.2f, IR synthesis %.2f, partition+FFT %.2f)  wall %.2f s  "
      "real-time factor %.1fx\n",
      (unsigned long long)t.frames, (unsigned long long)r.listeners.front().irsApplied,
      t.traceSeconds > 0 ? t.rays / t.traceSeconds : 0.0,
      t.traceSeconds > 0 ? t.segments / t.traceSeconds : 0.0, r.cacheEntries, r.cacheBytes / 1e6,
      r.cacheBudgetBytes / 1e6, r.cacheCoarseEntries, (unsigned long long)r.cacheMergedEntries,
      100.0 * r.cacheCoarseEnergyFraction, t.traceSeconds + t.synthesisSeconds + t.prepareSeconds,
      t.traceSeconds, t.synthesisSeconds, t.prepareSeconds, r.wallSeconds,
      audioSeconds / r.wallSeconds);
  std::printf("energy beyond the IR length %.3g %% of the last response (largest per pair)  "
              "IR sets lost %llu\n",
              100.0 * r.droppedEnergyFraction, (unsigned long long)r.irsLost);
}

/// Terminal raw mode for --interactive (restored on destruction).
class RawTerminal {
 public:
  RawTerminal() {
    if (!isatty(STDIN_FILENO) || tcgetattr(STDIN_FILENO, &saved_) != 0) return;
    termios raw = saved_;
    raw.c_lflag &= ~tcflag_t(ICANON | ECHO);
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    active_ = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
  }
  ~RawTerminal() {
    if (active_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
  }
  /// Next key, or 0 if none is waiting. Arrow keys come back as 'U', 'D', 'L', 'R' + 256.
  int key() {
    pollfd p{STDIN_FILENO, POLLIN, 0};
    if (poll(&p, 1, 0) <= 0) return 0;
    unsigned char c = 0;
    if (read(STDIN_FILENO, &c, 1) != 1) return 0;
    if (c != 27) return c;
    unsigned char seq[2] = {0, 0};
    if (read(STDIN_FILENO, seq, 2) != 2 || seq[0] != '[') return 27;
    switch (seq[1]) {
      case 'A':
        return 256 + 'U';
      case 'B':
        return 256 + 'D';
      case 'C':
        return 256 + 'R';
      case 'D':
        return 256 + 'L';
    }
    return 0;
  }

 private:
  termios saved_{};
  bool active_ = false;
};

int listDevices() {
  const auto devices = audio::listOutputDevices();
  if (devices.empty()) {
    std::printf(
        "no audio output devices (start a JACK server, e.g. jackd -d dummy -r 48000 "
        "-p 128, or render with --offline OUT.wav)\n");
    return 0;
  }
  for (const auto& d : devices)
    std::printf("%s%-40s  %-28s  %d ch  %.0f Hz  %.1f ms\n", d.isDefault ? "* " : "  ",
                d.spec().c_str(), d.hostApi.c_str(), d.maxOutputChannels, d.defaultSampleRate,
                d.defaultLowOutputLatency * 1e3);
  return 0;
}

/// --stats FILE.json: what a live run measured, for scripts and CI (docs/live.md "Statistics
/// file"). Loads are callback durations as a percentage of the block period; latencies are
/// motion-to-sound (pose published -> first block rendered with the IR traced for it).
void writeLiveStats(const std::string& path, const std::string& scenePath,
                    const audio::AudioOutput& output,
                    const audio::AudioOutput::Scheduling& scheduling, const LiveSession& session,
                    const LiveSession::Status& st, const audio::CallbackStats::Snapshot& cb,
                    const audio::CallbackStats::Snapshot& swap,
                    const audio::CallbackStats::Snapshot& noSwap) {
  using Json = nlohmann::ordered_json;
  auto load = [&](const audio::CallbackStats::Snapshot& s) {
    return Json{{"median", output.loadPercent(s.quantileNs(0.5))},
                {"p99", output.loadPercent(s.quantileNs(0.99))},
                {"p99_9", output.loadPercent(s.quantileNs(0.999))},
                {"max", output.loadPercent(s.maxNs)}};
  };
  const auto lat = session.latencyStats().snapshot();
  auto ms = [](uint64_t ns) { return double(ns) * 1e-6; };
  Json j = {
      {"scene", scenePath},
      {"sample_rate_hz", output.sampleRate()},
      {"block_frames", output.blockSize()},
      {"device", output.device().spec()},
      {"callback_scheduling",
       {{"known", scheduling.known},
        {"policy", scheduling.policy},
        {"priority", scheduling.priority},
        {"real_time", scheduling.realTime}}},
      {"callbacks", cb.callbacks},
      {"xruns", cb.xruns},
      {"late_callbacks", st.lateCallbacks},
      {"rejected_callbacks", st.rejectedCallbacks},
      {"nan_blocks", st.nanBlocks},
      // The long partitions are computed inside the callback, spread over the blocks of their
      // period (docs/live.md): there are no convolution worker threads that could miss one.
      {"worker_deadline_misses", 0},
      {"worker_threads", 0},
      {"callback_load_percent", load(cb)},
      {"render_load_percent", {{"with_ir_swap", load(swap)}, {"without_ir_swap", load(noSwap)}}},
      {"propagation_frames", st.frames},
      {"rays_per_frame",
       {{"last", st.raysPerFrame},
        {"min", st.raysPerFrameMin},
        {"scene", st.raysPerFrameScene},
        {"reduced_frames", st.reducedFrames}}},
      {"irs_applied", st.irsApplied},
      {"irs_dropped", st.irsDropped},
      {"irs_lost", st.irsLost},
      {"dropped_energy_fraction", st.droppedEnergyFraction},
      {"motion_to_sound_latency_ms",
       {{"count", lat.callbacks},
        {"median", ms(lat.quantileNs(0.5))},
        {"p95", ms(lat.quantileNs(0.95))},
        {"p99", ms(lat.quantileNs(0.99))},
        {"max", ms(lat.maxNs)}}},
      {"limiter",
       {{"limited_frames", st.limitedFrames},
        {"over_ceiling_frames", st.overCeilingFrames},
        {"max_reduction_db", st.limiterMaxReductionDb}}}};
  const std::string text =
      j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
  TempOutputFile file(path);
  file.writeAll(text.data(), text.size());
  file.commit();
}

int runLive(Flags& fl) {
  const auto shared = std::make_shared<SceneDesc>(loadScene(fl.scene));
  SceneDesc& scene = *shared;
  applyAudioOverrides(scene, fl);
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (fl.listener.empty() && scene.listeners.size() > 1)
    std::fprintf(stderr, "note: playing listener \"%s\" of %zu (choose with --listener NAME)\n",
                 scene.listeners[0].name.c_str(), scene.listeners.size());
  PropagationSettings settings = applyOverrides(scene, fl);
  // Live: leave one core to the audio thread unless --threads says otherwise (measured on 2
  // cores: 245 late blocks in 20 s with both cores tracing, 24 with one; docs/live.md).
  if (!fl.hasThreads) settings.threads = std::max(1, int(std::thread::hardware_concurrency()) - 1);
  if (fl.hasBlockSize) {
    if (fl.blockSize < 16 || fl.blockSize > 8192)
      throw InputError("command line", "--block-size", "must be in 16..8192 samples");
    scene.audio.blockSize = int(fl.blockSize);
  }
  if (fl.hasDuration && !(fl.duration > 0.0 && fl.duration <= kMaxDurationSeconds))
    throw InputError("command line", "--duration",
                     "must be in (0, " + std::to_string(int(kMaxDurationSeconds)) + "] seconds");
  checkOutputs(scene, fl);
  requireSignal(scene);
  checkSetup(scene, settings, 0.0, true);
  const auto dry = std::make_shared<const DrySignals>(loadDrySignals(scene));
  for (const std::string& n : dry->notes) std::fprintf(stderr, "note: %s\n", n.c_str());

  LiveSession::Options lo;
  lo.listener = selectedListener(scene, fl);
  lo.deviceChannels = 2;
  lo.latencyTargetSeconds = fl.latencyTargetMs * 1e-3;
  const double duration = fl.hasDuration ? fl.duration : 1e9;
  if (!fl.record.empty()) lo.recordSeconds = std::min(duration, 3600.0);
  LiveSession session(shared, settings, dry, lo);

  audio::AudioOutput::Options ao;
  ao.device = fl.device;
  ao.sampleRate = scene.audio.sampleRate;
  ao.channels = 2;
  ao.blockSize = scene.audio.blockSize;
  std::unique_ptr<audio::AudioOutput> output;
  try {
    output = std::make_unique<audio::AudioOutput>(ao, &LiveSession::renderCallback, &session);
  } catch (const std::exception& e) {
    // One line: the device layer's reason, plus the way out if it does not already say it.
    const std::string why = e.what();
    if (why.find("--offline") != std::string::npos)
      std::fprintf(stderr, "dpc-demo: %s\n", why.c_str());
    else
      std::fprintf(stderr,
                   "dpc-demo: %s; render with --offline OUT.wav, or start a JACK server "
                   "(jackd -d dummy -r %d -p 128); --list-devices shows what PortAudio sees\n",
                   why.c_str(), scene.audio.sampleRate);
    return 3;
  }
  std::fprintf(stderr, "playing on %s (%s), %.0f Hz, block %d, output latency %.1f ms\n",
               output->device().spec().c_str(), output->device().hostApi.c_str(),
               output->sampleRate(), output->blockSize(), output->outputLatency() * 1e3);

  // Pose: the trajectory on a wall clock (space pauses it), or the keyboard. Every listener is
  // traced each frame; 'l' plays the scene's next one (the keyboard then moves that one).
  size_t playedIndex = session.playedListener();
  const ListenerDesc* played = &scene.listeners[playedIndex];
  double sceneTime = 0.0;
  bool paused = false, manual = false;
  glm::vec3 position = listenerPositionAt(*played, 0.0);
  float yawOffset = 0.f;  // Q/E turn the head relative to the trajectory's heading
  float yaw = listenerOrientationAt(*played, 0.0).yawRadians;
  session.setPose(position, yaw, 0.0);
  // The callback thread's scheduling, read once a callback has run (reported, and in --stats).
  audio::AudioOutput::Scheduling scheduling;
  std::unique_ptr<RawTerminal> terminal;
  if (fl.interactive) {
    terminal = std::make_unique<RawTerminal>();
    std::fprintf(stderr,
                 "keys: arrows/WASD move, Q/E turn, space pauses the trajectory, l next "
                 "listener, q quits\n");
  }
  session.start();
  output->start();
  const auto start = std::chrono::steady_clock::now();
  auto last = start, lastStatus = start;
  const auto statsAtStart = output->stats().snapshot();
  bool quit = false;
  const bool tty = isatty(STDERR_FILENO);
  while (!quit) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    if (std::chrono::duration<double>(now - start).count() >= duration) break;
    if (terminal) {
      for (int k = terminal->key(); k; k = terminal->key()) {
        // Orientation convention (scene/scene.h): forward = (cos yaw, 0, -sin yaw).
        const glm::vec3 forward(std::cos(yaw), 0.f, -std::sin(yaw));
        const glm::vec3 right(std::sin(yaw), 0.f, std::cos(yaw));
        const float step = 0.25f, turn = float(std::numbers::pi / 12);
        switch (k) {
          case 'q':
            quit = true;
            break;
          case ' ':
            paused = !paused;
            break;
          case 'l':
            playedIndex = (playedIndex + 1) % scene.listeners.size();
            played = &scene.listeners[playedIndex];
            session.selectListener(playedIndex);
            position = listenerPositionAt(*played, sceneTime);
            manual = false;
            std::fprintf(stderr, "\nlistener \"%s\"\n", played->name.c_str());
            break;
          case 'w':
          case 256 + 'U':
            position += forward * step;
            manual = true;
            break;
          case 's':
          case 256 + 'D':
            position -= forward * step;
            manual = true;
            break;
          case 'a':
          case 256 + 'L':
            position -= right * step;
            manual = true;
            break;
          case 'd':
          case 256 + 'R':
            position += right * step;
            manual = true;
            break;
          case 'Q':
            yawOffset += turn;
            break;  // turn left
          case 'E':
          case 'e':
            yawOffset -= turn;
            break;  // turn right
        }
      }
    }
    if (!paused && !manual) {
      sceneTime += dt;
      position = listenerPositionAt(*played, sceneTime);
    }
    const Orientation heading = listenerOrientationAt(*played, sceneTime);
    yaw = heading.yawRadians + yawOffset;
    // The others follow their trajectories.
    for (size_t i = 0; i < scene.listeners.size(); ++i)
      if (i != playedIndex) {
        const Orientation o = listenerOrientationAt(scene.listeners[i], sceneTime);
        session.setListenerPose(i, listenerPositionAt(scene.listeners[i], sceneTime), o.yawRadians,
                                sceneTime, o.pitchRadians);
      }
    session.setPose(position, yaw, sceneTime, heading.pitchRadians);
    if (std::chrono::duration<double>(now - lastStatus).count() >= 1.0) {
      lastStatus = now;
      if (!scheduling.known) {
        scheduling = output->callbackScheduling();
        if (scheduling.known)
          std::fprintf(stderr, "%saudio callback: %s priority %d%s\n", tty ? "\r" : "",
                       scheduling.policy, scheduling.priority,
                       scheduling.realTime ? " (real-time)"
                                           : ": real-time priority not granted (JACK: start jackd "
                                             "with -R; ALSA: needs rtprio, e.g. ulimit -r or "
                                             "/etc/security/limits.d), xruns are likely under load");
      }
      const auto st = session.status();
      const auto cb = output->stats().snapshot().since(statsAtStart);
      std::fprintf(stderr,
                   "%sframe %5.1f ms | rays %5d/%d | %6.0fk rays/s | cache %7zu %5.1f/%.0f MB "
                   "merged %llu "
                   "(%4.1f%%) | IR age %5.1f ms | "
                   "latency %5.1f/%5.1f ms | load %4.1f%% | xruns %llu | limiter %llu (-%.1f dB) | "
                   "t %.1f s%s",
                   tty ? "\r" : "", st.frameMs, st.raysPerFrame, st.raysPerFrameScene,
                   st.raysPerSecond / 1e3, st.cacheEntries, st.cacheBytes / 1e6,
                   st.cacheBudgetBytes / 1e6, (unsigned long long)st.cacheMergedEntries,
                   100.0 * st.cacheMergedEnergyFraction, st.irAgeMs, st.latencyMedianMs,
                   st.latencyP95Ms, output->loadPercent(cb.quantileNs(0.5)),
                   (unsigned long long)cb.xruns, (unsigned long long)st.limitedFrames,
                   st.limiterMaxReductionDb, sceneTime, tty ? "   " : "\n");
    }
  }
  output->stop();
  session.stop();
  if (tty) std::fprintf(stderr, "\n");
  const auto st = session.status();
  const auto cb = output->stats().snapshot().since(statsAtStart);
  const auto swap = session.renderStatsWithSwap().snapshot();
  const auto noSwap = session.renderStatsWithoutSwap().snapshot();
  if (!fl.record.empty()) {
    audio::AudioData rec = session.takeRecording();
    audio::writeWav(fl.record, rec, audio::SampleFormat::kFloat32);
    std::printf("wrote %s (%.2f s played, %llu samples dropped by the recorder)\n",
                fl.record.c_str(), double(rec.frames()) / scene.audio.sampleRate,
                (unsigned long long)st.recordDropped);
  }
  std::printf(
      "live: frames=%llu irs_applied=%llu irs_dropped=%llu blocks=%llu callbacks=%llu "
      "xruns=%llu nan_blocks=%llu late_callbacks=%llu rejected_callbacks=%llu "
      "latency_median_ms=%.1f "
      "latency_p95_ms=%.1f callback_load_median_pct=%.1f callback_load_max_pct=%.1f "
      "render_swap_p999_pct=%.1f render_noswap_p999_pct=%.1f limited_frames=%llu "
      "over_ceiling_frames=%llu limiter_max_reduction_db=%.2f rays_per_frame=%d "
      "rays_per_frame_min=%d rays_per_frame_scene=%d reduced_frames=%llu\n",
      (unsigned long long)st.frames, (unsigned long long)st.irsApplied,
      (unsigned long long)st.irsDropped, (unsigned long long)st.blocks,
      (unsigned long long)cb.callbacks, (unsigned long long)cb.xruns,
      (unsigned long long)st.nanBlocks, (unsigned long long)st.lateCallbacks,
      (unsigned long long)st.rejectedCallbacks, st.latencyMedianMs, st.latencyP95Ms,
      output->loadPercent(cb.quantileNs(0.5)), output->loadPercent(cb.maxNs),
      output->loadPercent(swap.quantileNs(0.999)), output->loadPercent(noSwap.quantileNs(0.999)),
      (unsigned long long)st.limitedFrames, (unsigned long long)st.overCeilingFrames,
      st.limiterMaxReductionDb, st.raysPerFrame, st.raysPerFrameMin, st.raysPerFrameScene,
      (unsigned long long)st.reducedFrames);
  if (!fl.stats.empty()) {
    writeLiveStats(fl.stats, fl.scene, *output, scheduling, session, st, cb, swap, noSwap);
    std::printf("wrote %s\n", fl.stats.c_str());
  }
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "dpc-demo: interactive sound propagation with the diffuse path cache.\n"
      "Plays SCENE.json live through PortAudio (JACK, ALSA, PulseAudio), or renders it offline\n"
      "to a WAV file (--offline), moving the listener along the scene's trajectory (or the\n"
      "keyboard with --interactive). Flags override the scene's propagation settings."};
  Flags fl;
  app.add_option("scene", fl.scene, "Scene file (JSON; see docs/scene-format.md)");
  app.add_flag("--list-devices", fl.listDevices, "List audio output devices and exit");
  app.add_option("--device", fl.device,
                 "Output device: NAME, HOSTAPI:NAME (e.g. jack:system), default: JACK if running");
  app.add_option("--block-size", fl.blockSize, "Audio block size in samples (live)");
  app.add_option("--record", fl.record, "Live: also write what was played to this WAV");
  app.add_option("--stats", fl.stats,
                 "Live: write xruns, late callbacks, callback load and motion-to-sound latency "
                 "percentiles, IRs applied and the callback's scheduling to this JSON file at "
                 "the end (docs/live.md)")
      ->type_name("FILE.json");
  app.add_option("--latency-target-ms", fl.latencyTargetMs,
                 "Live: motion-to-sound latency to stay under; frames take fewer rays when "
                 "needed (default 50; the frame period applies when it is shorter)");
  app.add_flag("--interactive", fl.interactive,
               "Live: arrows/WASD move, Q/E turn, space pauses, q quits");
  app.add_option("--listener", fl.listener,
                 "Render or play the scene's listener of this name (default: the first)");
  app.add_option("--offline", fl.offline, "Render offline to this WAV file (float32)");
  app.add_option("--duration", fl.duration,
                 "Seconds to render (default: longest source + IR length)");
  app.add_option("--seed", fl.seed, "Random seed (same seed: bit-identical output)");
  app.add_option("--rays", fl.rays, "Rays per source per frame");
  app.add_option("--max-order", fl.maxOrder, "Maximum reflection order");
  app.add_option("--tau", fl.tau, "Cache response time tau, seconds (0 = path tracing)");
  app.add_option("--cache-memory-mb", fl.cacheMb,
                 "DPC memory budget per source-listener pair, MB (default 64; beyond it old "
                 "entries are merged, not dropped)");
  app.add_option("--estimator", fl.estimator, "dpc | path_tracing");
  app.add_option("--dpc-weighting", fl.weighting,
                 "window (unbiased, answers within tau; default) | ema (unbiased, slower) | seed "
                 "(thesis eq. 3.2; biased high)");
  app.add_option("--threads", fl.threads, "Tracing threads (0 = all cores)");
  app.add_option("--ir-out", fl.irOut, "Also write the last frame's IR (all channels) as WAV");
  app.add_option("--er-out", fl.erOut,
                 "Offline: also write each source's last-frame energy response per octave band "
                 "in 1 ms bins, direct sound marked, as CSV (docs/validation.md)");
  app.add_option("--gain-db", fl.gainDb,
                 "Fixed output gain in dB (default: normalise the peak to -1 dBFS)");
  app.add_flag("--quiet", fl.quiet, "No progress bar");
  app.add_option("--output", fl.output,
                 "mono | stereo | binaural (default: the scene's audio.output)");
  app.add_option("--hrtf", fl.hrtf,
                 "SOFA file for binaural output (default: /usr/share/libmysofa/default.sofa)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, the same format and exit status as every other input error, with the closest
    // option name when a flag looks mistyped.
    std::string msg = e.what(), hint;
    for (char& c : msg)
      if (c == '\n' || (unsigned char)c < 0x20) c = ' ';
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
    std::fprintf(stderr, "dpc-demo: command line: %s%s\n", msg.c_str(), hint.c_str());
    return 1;
  }
  fl.hasDuration = app.count("--duration") > 0;
  fl.hasTau = app.count("--tau") > 0;
  fl.hasCacheMb = app.count("--cache-memory-mb") > 0;
  fl.hasGain = app.count("--gain-db") > 0;
  fl.hasSeed = app.count("--seed") > 0;
  fl.hasRays = app.count("--rays") > 0;
  fl.hasMaxOrder = app.count("--max-order") > 0;
  fl.hasThreads = app.count("--threads") > 0;
  fl.hasBlockSize = app.count("--block-size") > 0;
  try {
    if (fl.listDevices) return listDevices();
    if (fl.scene.empty()) {
      std::fprintf(stderr, "dpc-demo: a scene file is required (--help for usage)\n");
      return 1;
    }
    if (!fl.offline.empty() && !fl.stats.empty())
      throw InputError("command line", "--stats", "is for live runs (offline prints its summary)");
    if (app.count("--latency-target-ms") > 0) {
      if (!fl.offline.empty())
        throw InputError("command line", "--latency-target-ms", "is for live runs");
      if (!(fl.latencyTargetMs >= 1.0 && fl.latencyTargetMs <= 10000.0))
        throw InputError("command line", "--latency-target-ms", "must be in [1, 10000] ms");
    }
    if (fl.offline.empty() && !fl.erOut.empty())
      throw InputError("command line", "--er-out", "needs --offline (offline renders only)");
    if (fl.offline.empty()) return runLive(fl);
    return runOffline(fl);
  } catch (const InputError& e) {
    std::fprintf(stderr, "dpc-demo: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dpc-demo: error: %s\n", e.what());
    return 1;
  }
}
