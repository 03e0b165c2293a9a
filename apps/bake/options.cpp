#include "apps/bake/options.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <iostream>

#include "apps/cli_values.h"
#include "common/input_error.h"
#include "scene/limits.h"
#include "scene/scene.h"

namespace dpc::bake {
namespace {

constexpr const char* kDescription =
    "dpc-bake: bakes a scene's acoustics at a grid of probes into an HDF5 file.\n"
    "  dpc-bake SCENE.json --out BAKE.h5 --spacing M [--height M | --box X0 Y0 Z0 X1 Y1 Z1]\n"
    "           [--map MAP.csv]\n"
    "  dpc-bake --resume BAKE.h5 [SCENE.json] [--map MAP.csv]\n"
    "Under mpirun the probes are shared among the ranks; the file is the same for any number\n"
    "of ranks. The probes, file size and time are estimated first; over 100000 probes, 16 GB\n"
    "or 24 h the bake is refused unless --force. One dpc-bake writes a file at a time.\n"
    "The format: docs/bake-format.md. Exit status 0 on success, 1 on bad input,\n"
    "128 + n after stop signal n (SIGINT, SIGTERM, SIGHUP: the file then says which probes are\n"
    "done; --resume finishes it).";

void addOptions(CLI::App& app, Options& o) {
  app.add_option("SCENE", o.scene, "Scene file (JSON)")->type_name("FILE");
  app.add_option("--out", o.out, "The bake to write (HDF5). A file already there stays untouched until the new bake is "
                 "complete: it is built in OUT.partial (resumable with --resume OUT.partial)")
      ->type_name("FILE");
  app.add_option("--resume", o.resume, "Finish an incomplete bake (or rewrite its --map)")
      ->type_name("FILE")
      ->excludes("--out");
  app.add_option("--spacing", o.grid.spacingM, "Probe grid spacing, metres (> 0)")->type_name("M");
  app.add_option("--height", o.grid.heightM, "Probe height above the floor, metres (default 1.6)")
      ->type_name("M");
  app.add_option("--box", o.box,
                 "Probes on a 3-D lattice of --spacing in this box instead of the horizontal "
                 "grid: corners x0 y0 z0 x1 y1 z1, metres")
      ->expected(6)
      ->type_name("X0 Y0 Z0 X1 Y1 Z1")
      ->excludes("--height");
  app.add_option("--probes", o.probes,
                 "Probe positions instead of a grid: a text file, one 'x y z' (metres) a line")
      ->type_name("FILE")
      ->excludes("--spacing")
      ->excludes("--height")
      ->excludes("--box");
  app.add_option("--rays", o.settings.rays,
                 "Rays per source and frame (default: the scene's rays_per_frame)")
      ->type_name("N");
  app.add_option("--frames", o.settings.frames,
                 "Frames per probe, a multiple of 4 (the confidence intervals' sub-streams)")
      ->type_name("N");
  app.add_option("--threads", o.settings.threads, "Tracing threads per process (0: all cores)")
      ->type_name("N");
  app.add_option("--map", o.map,
                 "Write the parameter map (T20, T30, EDT, C50, C80, D50, G per band, STI, each "
                 "with its 95 % confidence half-width) as CSV")
      ->type_name("FILE");
}

/// The flags without a value.
void addFlags(CLI::App& app, Options& o) {
  app.add_flag("--quiet", o.quiet, "No progress line");
  app.add_flag("--force", o.force,
               "Bake even when the estimate is over the limits (100000 probes, 16 GB, 24 h) or "
               "more than the disk's free space (docs/bake.md)");
  app.add_flag("--json", o.json,
               "Print a JSON summary on stdout at the end: probes, seconds, probes/s, "
               "processes, bytes per probe sent to the writer, writer seconds per probe");
}

void check(bool ok, const std::string& flag, const std::string& problem) {
  if (!ok) throw InputError("command line", flag, problem);
}

void validate(const Options& o, const CLI::App& app) {
  const bool fresh = o.resume.empty();
  check(!fresh || !o.scene.empty(), "SCENE", "a scene file is required (or --resume BAKE.h5)");
  check(!fresh || !o.out.empty(), "--out", "the bake file is required");
  check(!fresh || o.spacingGiven || !o.probes.empty(), "--spacing",
        "the probe spacing (or --probes) is required");
  check(fresh || o.probes.empty(), "--resume", "a resumed bake keeps its own probes");
  check(
      fresh || (app.count("--spacing") == 0 && app.count("--height") == 0 &&
                app.count("--box") == 0 && app.count("--rays") == 0 && app.count("--frames") == 0),
      "--resume", "a resumed bake keeps its own grid, rays and frames");
  check(std::isfinite(o.grid.spacingM) && o.grid.spacingM > 0.0, "--spacing",
        valueText(o.grid.spacingM) + " m is not > 0");
  check(std::isfinite(o.grid.heightM) && o.grid.heightM >= 0.0, "--height",
        valueText(o.grid.heightM) + " m is not >= 0");
  check(o.settings.rays >= 1 && o.settings.rays <= kMaxBakeRays, "--rays",
        std::to_string(o.settings.rays) + " is outside [1, " + std::to_string(kMaxBakeRays) + "]");
  check(o.settings.frames >= o.settings.subStreams && o.settings.frames <= kMaxBakeFrames &&
            o.settings.frames % o.settings.subStreams == 0,
        "--frames",
        std::to_string(o.settings.frames) + " is not a multiple of " +
            std::to_string(o.settings.subStreams) + " in [" +
            std::to_string(o.settings.subStreams) + ", " + std::to_string(kMaxBakeFrames) + "]");
  check(o.settings.threads >= 0 && o.settings.threads <= kMaxTracingThreads, "--threads",
        std::to_string(o.settings.threads) + " is outside [0, " +
            std::to_string(kMaxTracingThreads) + "]");
}

}  // namespace

bool parseOptions(int argc, char** argv, Options& o) {
  CLI::App app(kDescription, "dpc-bake");
  addOptions(app, o);
  addFlags(app, o);
  refuseEmptyValues(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return false;
  } catch (const CLI::ParseError& e) {
    throw InputError("command line", "", e.what());
  }
  o.spacingGiven = app.count("--spacing") > 0;
  if (!o.box.empty()) {
    o.grid.box = true;
    o.grid.heightM = 0.0;
    o.grid.boxMin = glm::vec3(float(o.box[0]), float(o.box[1]), float(o.box[2]));
    o.grid.boxMax = glm::vec3(float(o.box[3]), float(o.box[4]), float(o.box[5]));
  }
  o.raysGiven = app.count("--rays") > 0;
  validate(o, app);
  return true;
}

}  // namespace dpc::bake
