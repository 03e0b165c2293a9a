// dpc-bench: speed and noise benchmarks. Prints one JSON document on stdout; progress on stderr.
//
//   dpc-bench propagation SCENE [--threads T] [--rays N] [--max-order D] [--frames F]
//                               [--tracing from_sources|from_listeners]
//                               [--no-roulette] [--record-surfaces] [--tau S] [--warmup-frames W]
//   dpc-bench noise SCENE [--rays N] [--frames F] [--tau S] [--walk-speed V]
//                         [--reference-frames M] [--threads T] [--max-order D]
//   dpc-bench dynamic [--rays N] [--frames F] [--parts step,objects,moving_source]
//                     (built-in scenes; no file)
//   dpc-bench listeners SCENE [--rays N] [--frames F] [--threads T] [--counts 1,2,4,8]
//   dpc-bench sources SCENE [--rays N] [--frames F] [--counts 1,4,16,64,256]
//                           [--tracing from_sources,from_listeners]
//   dpc-bench diffraction SCENE [--frames F]
//   dpc-bench live SCENE [--rays N] [--duration S] [--block-size B] [--frame-rate F]
//                        [--threads T] [--device SPEC]
//   dpc-bench budget SCENE|room-4x3x2.5 [--rays-list N ...]
//   dpc-bench convolve [--blocks B ...] [--seconds S] [--swap-ms M] [--no-uniform] [--cases C,...]
//                      [--overlap K]
//   dpc-bench load [--cells 25,50,...] [--panels P] [--crates C]   (generated terrains; no file)
//   dpc-bench wave [--volumes V ...] [--frequencies HZ ...] [--seconds S]   (boxes; no file)
//
// One file per benchmark family (bench/<family>_bench.h); this file holds the command line.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "bench/bake_bench.h"
#include "bench/bake_frame_bench.h"
#include "bench/bake_interp_bench.h"
#include "bench/bench_util.h"
#include "bench/budget_bench.h"
#include "bench/convolve_bench.h"
#include "bench/diffraction_bench.h"
#include "bench/dynamic_bench.h"
#include "bench/listeners_bench.h"
#include "bench/live_bench.h"
#include "bench/load_bench.h"
#include "bench/noise_bench.h"
#include "bench/propagation_bench.h"
#include "bench/sources_bench.h"
#include "bench/wave_bench.h"
#include "common/input_error.h"
#include "common/program_main.h"
#include "scene/enum_names.h"
#include "scene/limits.h"

namespace dpc::bench {
namespace {

/// Every subcommand's options (only the chosen subcommand's are parsed).
struct Options {
  CommonOptions common;
  PropagationOptions propagation;
  std::string propagationTracing = "from_sources";
  NoiseOptions noise;
  LiveOptions live;
  ListenersOptions listeners;
  SourcesOptions sources;
  std::vector<int> budgetRays = {1000, 10000, 100000};
  DynamicOptions dynamic;
  ConvolveOptions convolve;
  LoadOptions load;
  BakeBenchOptions bake;
  BakeInterpOptions bakeInterp;
  BakeFrameOptions bakeFrame;
  WaveBenchOptions wave;
};

/// The subcommands as CLI11 knows them (each is true once parsed).
struct Subcommands {
  CLI::App *propagation, *noise, *live, *listeners, *sources, *diffraction, *budget, *dynamic,
      *convolve, *load, *bake, *bakeInterp, *bakeFrame, *wave;
};

/// A flag's check: a number in [lo, hi]. CLI::Range lets NaN through (its comparisons are
/// false), which became a null report or the scene's default without a word.
CLI::Validator within(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || std::isnan(v)) return text + " is not a number";
        if (!(v >= lo && v <= hi))
          return text + " is outside [" + valueText(lo) + ", " + valueText(hi) + "]";
        return std::string();
      },
      "", "WITHIN");
}

/// The range of a scene field's limit (scene/limits.h) as a flag's check: one definition of
/// what a scene file and dpc-bench accept.
CLI::Validator limitRange(const char* field) {
  const Limit& l = limitOf(field);
  return within(l.min, l.max);
}

/// A subcommand that loads a scene, with the options every such benchmark takes.
CLI::App* addSceneBench(CLI::App& app, const char* name, const char* description,
                        CommonOptions& c) {
  CLI::App* sub = app.add_subcommand(name, description);
  sub->add_option("scene", c.scene, "Scene file")->required();
  sub->add_option("--threads", c.threads, "Tracing threads (0 = all cores)")
      ->check(within(0, 1024));
  sub->add_option("--rays", c.rays, "Rays per frame (default 4096)")
      ->check(limitRange("propagation.rays_per_frame"));
  sub->add_option("--max-order", c.maxOrder, "Maximum reflection order")
      ->check(limitRange("propagation.max_order"));
  sub->add_option("--frames", c.frames, "Frames to measure")->check(within(1, 1000000));
  sub->add_option("--tau", c.tau, "Cache response time tau, seconds")
      ->check(limitRange("propagation.cache_tau"));
  sub->add_option("--cache-memory-mb", c.cacheMb, "DPC memory budget per source, MB (> 0)")
      ->check(CLI::PositiveNumber);
  return sub;
}

CLI::App* addNoise(CLI::App& app, Options& o) {
  CLI::App* sub =
      addSceneBench(app, "noise", "DPC vs path tracing against a converged reference", o.common);
  sub->add_option("--walk-speed", o.noise.walkSpeed, "Listener speed along the trajectory, m/s")
      ->check(within(0.0, 100.0));
  sub->add_option("--reference-frames", o.noise.referenceFrames,
                  "Path-tracing frames per reference")
      ->check(within(1, 1000000));
  sub->add_option("--warmup", o.noise.warmup, "Frames before measuring (default 2 tau)")
      ->check(within(0, 1000000));
  sub->add_option("--pt-multipliers", o.noise.ptMultipliers, "Ray multipliers for path tracing")
      ->check(within(1, 4096));
  return sub;
}

CLI::App* addLive(CLI::App& app, Options& o) {
  CLI::App* sub =
      addSceneBench(app, "live", "Motion-to-sound latency and audio render load", o.common);
  sub->add_option("--duration", o.live.duration, "Seconds to run (default 20)")
      ->check(within(0.1, 86400.0));
  sub->add_option("--block-size", o.live.blockSize, "Audio block size (default 128)");
  sub->add_option("--frame-rate", o.live.frameRate,
                  "Propagation frames per second (default: scene)")
      ->check(limitRange("propagation.frame_rate"));
  sub->add_option("--device", o.live.device, "Audio device (default: a timer thread, no device)");
  sub->add_option("--late-bus-tolerance-db", o.live.lateBusToleranceDb,
                  "Hybrid rendering: a late bus keeps its IR while its decay's shape stays "
                  "within this many dB (0: synthesise every bus every frame; default 0.5)")
      ->check(within(0.0, 6.0));
  sub->add_option("--source-ir-tolerance-db", o.live.sourceIrToleranceDb,
                  "A source keeps its IR (its early part in hybrid rendering) while its exact "
                  "paths and energy response stay within this many dB (0: synthesise every IR "
                  "every frame; default 0.5)")
      ->check(within(0.0, 6.0));
  return sub;
}

CLI::App* addListeners(CLI::App& app, Options& o) {
  CLI::App* sub =
      addSceneBench(app, "listeners",
                    "Frame time for several listeners traced in one pass (1, 2, 4, 8)", o.common);
  sub->add_option("--warmup-frames", o.listeners.warmupFrames,
                  "Frames run before timing (cache fill, first-touch page faults; default 5)")
      ->check(within(0, 1000));
  sub->add_option("--counts", o.listeners.counts, "Listener counts (first = the reference)")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  return sub;
}

CLI::App* addSources(CLI::App& app, Options& o) {
  CLI::App* sub = addSceneBench(
      app, "sources",
      "Frame time, peak memory and per-source quality vs source count, both tracing directions",
      o.common);
  sub->add_option("--counts", o.sources.counts, "Source counts (first = the reference)")
      ->delimiter(',')
      ->check(within(1, 256));
  sub->add_option("--tracing", o.sources.tracing, "from_sources, from_listeners or both")
      ->delimiter(',')
      ->check(CLI::IsMember({"from_sources", "from_listeners", "auto"}));
  sub->add_option("--warmup-frames", o.sources.warmupFrames,
                  "Frames before timing; quality is read after them (default 20)")
      ->check(within(1, 1000));
  sub->add_option("--quality-sources", o.sources.qualitySources,
                  "Sources compared with a reference (default 4)")
      ->check(within(0, 256));
  sub->add_option("--rendering", o.sources.rendering,
                  "auto (default: hybrid beyond the late buses' count) | per_source | hybrid")
      ->check(CLI::IsMember({"auto", "per_source", "hybrid"}));
  sub->add_option("--max-from-sources", o.sources.maxFromSources,
                  "Largest source count traced from the sources (default 64)")
      ->check(within(1, 256));
  sub->add_option("--reference-frames", o.sources.referenceFrames,
                  "Path-tracing frames of each reference (4x rays; default 24)")
      ->check(within(2, 10000));
  sub->add_option("--keep-tolerance-db", o.sources.keepToleranceDb,
                  "Keep source IRs (early parts in hybrid rendering) and late-bus IRs while "
                  "their inputs hold within this many dB, as a live session does (default 0: "
                  "every IR every frame, as offline renders do)")
      ->check(within(0.0, 6.0));
  return sub;
}

CLI::App* addDynamic(CLI::App& app, Options& o) {
  CLI::App* sub = app.add_subcommand(
      "dynamic", "Door step response per estimator and tau; moving-object frame time");
  sub->add_option("--parts", o.dynamic.parts,
                  "Comma-separated parts to run: step, objects, moving_source (default all)");
  sub->add_option("--rays", o.dynamic.rays, "Rays per frame (default 2048)");
  sub->add_option("--frames", o.dynamic.frames, "Frames per object-count measurement (default 20)");
  return sub;
}

CLI::App* addConvolve(CLI::App& app, Options& o) {
  CLI::App* sub = app.add_subcommand(
      "convolve", "Convolver CPU: non-uniform dpc (with/without IR swaps) vs zita-convolver");
  sub->add_option("--blocks", o.convolve.blocks, "Block sizes (default 64 128 256 512)")
      ->check(limitRange("audio.block_size"));
  sub->add_option("--seconds", o.convolve.seconds, "Audio seconds per run (default 3)")
      ->check(within(0.1, 600.0));
  sub->add_option("--swap-ms", o.convolve.swapIntervalMs, "IR swap interval, ms (default 66)")
      ->check(within(0.1, 10000.0));
  sub->add_flag("!--no-uniform", o.convolve.uniform, "Skip the uniform convolver");
  sub->add_option("--overlap", o.convolve.overlap,
                  "Partitions each level of dpc's layout reaches into the next, 0..4 (default " +
                      std::to_string(audio::NonUniformLayout::kDefaultOverlap) +
                      "; 0: levels meet at a hard boundary)")
      ->check(CLI::Range(0, audio::NonUniformLayout::kMaxOverlap));
  sub->add_option("--cases", o.convolve.cases,
                  "Comma-separated cases to run: mono, stereo, 2x3, 16x2, hybrid64 (64 sources' "
                  "early parts of 0.228 s), late4 (4 late buses of 2 s); default all")
      ->delimiter(',')
      ->check(CLI::IsMember({"mono", "stereo", "2x3", "16x2", "hybrid64", "late4"}));
  return sub;
}

CLI::App* addLoad(CLI::App& app, Options& o) {
  CLI::App* sub = app.add_subcommand(
      "load", "Scene load time (OBJ, geometry, Embree, diffraction edges) vs triangle count");
  sub->add_option("--cells", o.load.cells,
                  "Terrain sizes, cells per side (2 cells^2 triangles; default 25,...,708)")
      ->delimiter(',')
      ->check(within(1, 4000));
  sub->add_option("--panels", o.load.panels, "Panels standing on the terrain (default 16)")
      ->check(within(0, 10000));
  sub->add_option("--crates", o.load.crates,
                  "Solid 0.25 m crates on it, every face a narrow face (default 0)")
      ->check(within(0, 100000));
  return sub;
}

CLI::App* addBake(CLI::App& app, Options& o) {
  CLI::App* sub = app.add_subcommand(
      "bake", "dpc-bake probes/s vs probe count: 1 and 2 threads, mpirun -np 2; scaling plan");
  sub->add_option("scene", o.bake.scene, "Scene file")->required();
  sub->add_option("--spacings", o.bake.spacings, "Grid spacings, m (default 2 1 0.5)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--rays", o.bake.rays, "Rays per source and frame (default 1000)")
      ->check(within(1, 1 << 20));
  sub->add_option("--frames", o.bake.frames, "Frames per probe, a multiple of 4 (default 8)");
  sub->add_option("--bake", o.bake.bake, "The dpc-bake program (default: beside dpc-bench)");
  sub->add_option("--mpirun", o.bake.mpirun, "mpirun program (empty: skip the MPI runs)");
  return sub;
}

CLI::App* addBakeInterp(CLI::App& app, Options& o) {
  CLI::App* sub = app.add_subcommand(
      "bake-interp",
      "Baked playback: interpolation error vs probe spacing (diffuse box), cost, memory");
  sub->add_option("--spacings", o.bakeInterp.spacings, "Probe spacings, m (default 0.5 1 2 4)")
      ->check(within(0.1, 4.0));
  sub->add_option("--points", o.bakeInterp.points, "Test points (default 6)")
      ->check(within(1, 1000));
  sub->add_option("--rays", o.bakeInterp.rays, "Rays per frame (default 4000)")
      ->check(within(1, 1 << 20));
  sub->add_option("--frames", o.bakeInterp.frames, "Frames per response (default 8)")
      ->check(within(1, 1000));
  sub->add_option("--threads", o.bakeInterp.threads, "Tracing threads (0 = all cores)")
      ->check(within(0, 1024));
  return sub;
}

CLI::App* addBakeFrame(CLI::App& app, Options& o) {
  CLI::App* sub = addSceneBench(
      app, "bake-frame",
      "Frame cost with every static source played from a bake (not traced) vs all live",
      o.common);
  sub->add_option("--counts", o.bakeFrame.counts, "Static source counts (default 1 4 16)")
      ->check(within(1, 4096));
  sub->add_option("--tracing", o.bakeFrame.tracing,
                  "Tracing directions (default from_sources from_listeners)")
      ->check(CLI::IsMember({"from_sources", "from_listeners"}));
  sub->add_option("--warmup-frames", o.bakeFrame.warmupFrames, "Untimed frames first (default 5)")
      ->check(within(0, 1000));
  return sub;
}

/// Defines every subcommand, in the order --help lists them.
Subcommands addSubcommands(CLI::App& app, Options& o) {
  Subcommands s{};
  s.propagation =
      addSceneBench(app, "propagation", "Frame time and segments/s vs bare Embree", o.common);
  s.propagation->add_flag("--no-roulette", o.propagation.noRoulette, "Trace every ray to max order");
  s.propagation->add_flag("--record-surfaces", o.propagation.recordSurfaces,
                          "Record each frame's energy per surface (dpc studio's heat map)");
  s.propagation
      ->add_option("--warmup-frames", o.propagation.warmupFrames,
                   "Untimed frames first (cache growth, first-touch page faults; default 5)")
      ->check(within(0, 1000));
  s.propagation
      ->add_option("--tracing", o.propagationTracing,
                   "from_sources or from_listeners: the full frame's tracing direction (the bare "
                   "loops start where its rays do)")
      ->check(CLI::IsMember({"from_sources", "from_listeners"}))
      ->capture_default_str();
  s.noise = addNoise(app, o);
  s.live = addLive(app, o);
  s.listeners = addListeners(app, o);
  s.sources = addSources(app, o);
  s.diffraction = addSceneBench(
      app, "diffraction",
      "Edge diffraction: edges found at load time, cost per source-listener pair", o.common);
  s.budget = addSceneBench(
      app, "budget",
      "Cache entries, bytes and budget bias vs rays per frame (scene or room-4x3x2.5)", o.common);
  s.budget->add_option("--rays-list", o.budgetRays, "Rays per frame values");
  s.dynamic = addDynamic(app, o);
  s.convolve = addConvolve(app, o);
  s.load = addLoad(app, o);
  s.bake = addBake(app, o);
  s.bakeInterp = addBakeInterp(app, o);
  s.bakeFrame = addBakeFrame(app, o);
  s.wave = app.add_subcommand("wave",
                              "Wave band (FDTD): time and memory per simulated second and cubic "
                              "metre at 250 and 500 Hz; predicted scaling over MPI ranks");
  s.wave->add_option("--volumes", o.wave.volumes, "Box volumes, m^3 (default 50 200 800)")
      ->check(within(1.0, 1e5));
  s.wave
      ->add_option("--frequencies", o.wave.frequencies, "Maximum frequencies, Hz (default 250 500)")
      ->check(within(20.0, 4000.0));
  s.wave->add_option("--seconds", o.wave.seconds, "Simulated seconds per run (default 0.25)")
      ->check(within(0.01, 60.0));
  return s;
}

/// Runs the parsed subcommand; returns the exit status.
int run(const Subcommands& s, const Options& o) {
  if (*s.propagation) {
    PropagationOptions p = o.propagation;
    p.tracing = *parseTracing(o.propagationTracing);
    return benchPropagation(o.common, p);
  }
  if (*s.dynamic) return benchDynamic(o.dynamic);
  if (*s.listeners) return benchListeners(o.common, o.listeners);
  if (*s.sources) return benchSources(o.common, o.sources);
  if (*s.convolve) return benchConvolve(o.convolve);
  if (*s.bake) return benchBake(o.bake);
  if (*s.bakeInterp) return benchBakeInterp(o.bakeInterp);
  if (*s.bakeFrame) return benchBakeFrame(o.common, o.bakeFrame);
  if (*s.budget) return benchBudget(o.common, o.budgetRays);
  if (*s.diffraction) return benchDiffraction(o.common);
  if (*s.live) return benchLive(o.common, o.live);
  if (*s.load) return benchLoad(o.load);
  if (*s.wave) return benchWave(o.wave);
  return benchNoise(o.common, o.noise);
}

}  // namespace
}  // namespace dpc::bench

int main(int argc, char** argv) {
  CLI::App app{"dpc-bench: propagation speed and DPC noise benchmarks (JSON on stdout)"};
  app.require_subcommand(1);
  dpc::bench::Options o;
  const dpc::bench::Subcommands subs = dpc::bench::addSubcommands(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line and exit status 1, as every dpc program's input errors.
    std::string msg = e.what();
    for (char& ch : msg)
      if (ch == '\n' || (unsigned char)ch < 0x20) ch = ' ';
    std::fprintf(stderr, "dpc-bench: command line: %s\n", msg.c_str());
    return 1;
  }
  return dpc::runReportingErrors("dpc-bench", [&] { return dpc::bench::run(subs, o); });
}
