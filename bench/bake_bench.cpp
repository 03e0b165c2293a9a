#include "bench/bake_bench.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "bench/bench_util.h"

namespace dpc::bench {
namespace {

/// dpc-bake beside this program's build folder (build/bench/dpc-bench -> build/apps/dpc-bake).
std::string defaultBake() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return (self.parent_path().parent_path() / "apps" / "dpc-bake").string();
}

/// Runs a shell command and returns its stdout; throws when it exits non-zero.
std::string capture(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen(command.c_str(), "r"), ::pclose);
  if (!pipe) throw std::runtime_error("cannot run: " + command);
  std::string out;
  char buf[4096];
  while (size_t n = std::fread(buf, 1, sizeof buf, pipe.get())) out.append(buf, n);
  if (::pclose(pipe.release()) != 0) throw std::runtime_error("failed: " + command);
  return out;
}

struct Mode {
  const char* name;
  int threads;   ///< per process
  int processes; ///< 1: no mpirun
};

Json runOnce(const BakeBenchOptions& o, const std::string& bake, const Mode& m, double spacing,
             const std::string& out) {
  std::string cmd = bake + " " + o.scene + " --out " + out + " --spacing " +
                    std::to_string(spacing) + " --rays " + std::to_string(o.rays) +
                    " --frames " + std::to_string(o.frames) + " --threads " +
                    std::to_string(m.threads) + " --quiet --json 2>/dev/null";
  if (m.processes > 1)
    cmd = o.mpirun + " -q --allow-run-as-root --oversubscribe -np " +
          std::to_string(m.processes) + " " + cmd;
  Json r = Json::parse(capture(cmd));
  r["mode"] = m.name;
  r["spacing_m"] = spacing;
  std::fprintf(stderr, "bake %-22s spacing %.2f m: %4d probes, %.3g probes/s\n", m.name, spacing,
               r["probes"].get<int>(), r["probes_per_second"].get<double>());
  return r;
}

/// The gather's throughput bound for n ranks from one-thread probe cost and the writer's cost
/// per probe: min(n / t_probe, 1 / t_commit, link / bytes).
Json plan(const BakeBenchOptions& o, const Json& single) {
  const double tProbe = 1.0 / single["probes_per_second"].get<double>();
  const double tCommit = single["commit_seconds_per_probe"].get<double>();
  const double bytes = single["bytes_per_probe"].get<double>();
  Json curve = Json::array();
  for (const double ranks : {1.0, 2.0, 8.0, 64.0, 512.0, 2048.0, 16384.0}) {
    const double pps = std::min({ranks / tProbe, 1.0 / tCommit, o.planLinkBytesPerSecond / bytes});
    curve.push_back({{"ranks", ranks}, {"probes_per_second", pps}});
  }
  const double ranks = o.planNodes * o.planCoresPerNode;
  const double pps = std::min({ranks / tProbe, 1.0 / tCommit, o.planLinkBytesPerSecond / bytes});
  return {{"model", "min(ranks / probe_seconds, 1 / commit_seconds, link / bytes_per_probe)"},
          {"probe_seconds_one_thread", tProbe},
          {"commit_seconds_per_probe", tCommit},
          {"bytes_per_probe", bytes},
          {"curve", curve},
          {"level", {{"probes", o.planProbes}, {"nodes", o.planNodes},
                     {"cores_per_node", o.planCoresPerNode}, {"ranks", ranks},
                     {"probes_per_second", pps}, {"hours", o.planProbes / pps / 3600.0}}}};
}

}  // namespace

int benchBake(const BakeBenchOptions& o) {
  const std::string bake = o.bake.empty() ? defaultBake() : o.bake;
  const std::string out =
      (std::filesystem::temp_directory_path() / ("dpc-bench-bake-" + std::to_string(::getpid()) +
                                                 ".h5")).string();
  const bool mpi = !o.mpirun.empty() && std::system(("command -v " + o.mpirun +
                                                     " >/dev/null").c_str()) == 0;
  std::vector<Mode> modes = {{"1 process, 1 thread", 1, 1}, {"1 process, 2 threads", 2, 1}};
  if (mpi) modes.push_back({"mpirun -np 2, 1 thread", 1, 2});
  Json runs = Json::array();
  for (const double spacing : o.spacings)
    for (const Mode& m : modes) runs.push_back(runOnce(o, bake, m, spacing, out));
  std::filesystem::remove(out);
  Json report = {{"benchmark", "bake"}, {"scene", o.scene}, {"rays", o.rays},
                 {"frames", o.frames}, {"cores", ::sysconf(_SC_NPROCESSORS_ONLN)}, {"runs", runs}};
  // The model's costs from the one-thread run with the most probes (the last spacing's first).
  report["prediction"] = plan(o, runs[runs.size() - modes.size()]);
  std::cout << report.dump(2) << "\n";
  return 0;
}

}  // namespace dpc::bench
