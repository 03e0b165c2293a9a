// `dpc-bench convolve`: the non-uniform convolver (audio/nonuniform_convolver.h), with and
// without an IR swap every swapIntervalMs, the uniform convolver (audio/convolver.h) and
// zita-convolver on the same IRs and input, one run, one process.
//
// CPU time: getrusage(RUSAGE_SELF) user + system over a measurement counts every thread of the
// process (zita's worker threads included); nothing else runs in the process meanwhile.
// Per-block figures are the calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID) around each
// block: for dpc that is all its work, for zita only the part done in process() (the tail
// levels run in its worker threads). zita runs with process(sync = true), so its workers always
// finish and the run needs no real-time pacing (waiting costs no CPU).
#include "bench/convolve_bench.h"

#include <sched.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

#include "audio/convolver.h"
#include "audio/nonuniform_convolver.h"
#include "bench/bench_util.h"

#ifdef DPC_HAVE_ZITA
#include <zita-convolver.h>
#endif

namespace dpc::bench {
namespace {

using nlohmann::json;

double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Case {
  const char* id;    ///< short name for --cases
  const char* name;
  int sources, channels;
  double irSeconds;
  /// Source s's IRs are silent before its onset, onsetMaxSeconds (s + 0.5) / sources: the
  /// direct sound's delay of sources spread over distances, as hybrid rendering's early parts.
  double onsetMaxSeconds = 0.0;
};

/// Signals shared by every convolver of a case: dry inputs and two IR variants (for swaps).
struct CaseData {
  int block = 0, sources = 0, channels = 0;
  int overlap = 0;  ///< the layout's K
  size_t irSamples = 0, blocks = 0;
  std::vector<std::vector<float>> input;   ///< per source, blocks * block samples
  std::vector<std::vector<float>> irs[2];  ///< variant -> [s * channels + c]
};

CaseData makeData(const Case& cs, int block, const ConvolveOptions& o) {
  CaseData d;
  d.block = block;
  d.overlap = o.overlap;
  d.sources = cs.sources;
  d.channels = cs.channels;
  d.irSamples = size_t(std::lround(cs.irSeconds * o.sampleRate));
  d.blocks = size_t(std::ceil(o.seconds * o.sampleRate / block));
  std::mt19937 rng(1234);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  for (int s = 0; s < cs.sources; ++s) {
    d.input.emplace_back(d.blocks * size_t(block));
    for (float& v : d.input.back()) v = 0.1f * noise(rng);
  }
  // Decaying noise (60 dB over the IR: a reverberation tail), different per variant, from
  // the source's onset on.
  for (auto& variant : d.irs)
    for (int i = 0; i < cs.sources * cs.channels; ++i) {
      const double onset = cs.onsetMaxSeconds * (i / cs.channels + 0.5) / cs.sources;
      const size_t first = std::min(d.irSamples, size_t(std::lround(onset * o.sampleRate)));
      variant.emplace_back(d.irSamples, 0.0f);
      for (size_t n = first; n < d.irSamples; ++n)
        variant.back()[n] = 0.05f * noise(rng) * std::exp(-6.9f * float(n) / float(d.irSamples));
    }
  return d;
}

struct Timing {
  std::vector<double> blockSeconds;  ///< calling thread, per block
  double processSeconds = 0.0;       ///< all threads over the run
  json toJson(double period) const {
    std::vector<double> pct(blockSeconds);
    for (double& v : pct) v *= 100.0 / period;
    return {{"cpu_percent_mean", 100.0 * processSeconds / (period * double(blockSeconds.size()))},
            {"cpu_percent_median", percentile(pct, 0.5)},
            {"cpu_percent_p99", percentile(pct, 0.99)},
            {"cpu_percent_max", pct.empty() ? NAN : *std::max_element(pct.begin(), pct.end())}};
  }
};

/// IR sets for the non-uniform convolver: prepared on demand from one of the case's two IR
/// variants, recycled once the convolver retires them; the CPU time of each preparation kept.
class IrSetPool {
 public:
  IrSetPool(const CaseData& d, const audio::NonUniformLayout& layout) : d_(d), layout_(layout) {}

  /// A set holding IR variant `variant` (allocates a set when none is free).
  audio::NonUniformIrSet* prepared(int variant) {
    if (free_.empty()) {
      pool_.push_back(std::make_unique<audio::NonUniformIrSet>(layout_, d_.sources, d_.channels));
      free_.push_back(pool_.back().get());
    }
    audio::NonUniformIrSet* set = free_.back();
    free_.pop_back();
    const double t0 = threadCpuSeconds();
    for (int s = 0; s < d_.sources; ++s) {
      std::vector<const float*> ch;
      for (int c = 0; c < d_.channels; ++c)
        ch.push_back(d_.irs[variant][size_t(s * d_.channels + c)].data());
      set->prepare(s, ch.data(), d_.irSamples);
    }
    prepareSeconds_.push_back(threadCpuSeconds() - t0);
    return set;
  }
  void recycle(const audio::NonUniformIrSet* set) {
    free_.push_back(const_cast<audio::NonUniformIrSet*>(set));
  }
  size_t allocated() const { return pool_.size(); }
  const std::vector<double>& prepareSeconds() const { return prepareSeconds_; }

 private:
  const CaseData& d_;
  const audio::NonUniformLayout& layout_;
  std::vector<std::unique_ptr<audio::NonUniformIrSet>> pool_;
  std::vector<audio::NonUniformIrSet*> free_;
  std::vector<double> prepareSeconds_;
};

/// The non-uniform convolver over the case; swapEvery > 0: a new IR set every swapEvery blocks
/// (prepared between blocks, its CPU time reported apart: the propagation thread's work).
json runNonUniform(const CaseData& d, int swapEvery, bool measure, std::vector<float>* firstOut,
                   double period) {
  using namespace dpc::audio;
  NonUniformLayout layout(
      d.block, d.irSamples, NonUniformLayout::kDefaultMaxPartition,
      measure ? ConvolverLayout::Planning::kMeasure : ConvolverLayout::Planning::kEstimate,
      d.overlap);
  NonUniformConvolver conv(layout, d.sources, d.channels);
  IrSetPool pool(d, layout);
  conv.setNextIr(pool.prepared(0));
  std::vector<std::vector<float>> out(size_t(d.channels), std::vector<float>(size_t(d.block)));
  std::vector<float*> outPtr;
  for (auto& o : out) outPtr.push_back(o.data());
  std::vector<const float*> in(size_t(d.sources));
  if (firstOut) firstOut->clear();
  Timing t;
  int swaps = 0;
  double excluded = 0.0;  // IR preparation, excluded from the convolver's process CPU
  const double p0 = processCpuSeconds();
  for (size_t k = 0; k < d.blocks; ++k) {
    if (swapEvery > 0 && k > 0 && k % size_t(swapEvery) == 0) {
      const double e0 = processCpuSeconds();
      while (const NonUniformIrSet* r = conv.takeRetired()) pool.recycle(r);
      NonUniformIrSet* set = pool.prepared(++swaps % 2);
      if (!conv.setNextIr(set)) pool.recycle(set);
      excluded += processCpuSeconds() - e0;
    }
    for (int s = 0; s < d.sources; ++s)
      in[size_t(s)] = d.input[size_t(s)].data() + k * size_t(d.block);
    const double t0 = threadCpuSeconds();
    conv.process(in.data(), outPtr.data());
    t.blockSeconds.push_back(threadCpuSeconds() - t0);
    if (firstOut) firstOut->insert(firstOut->end(), out[0].begin(), out[0].end());
  }
  t.processSeconds = processCpuSeconds() - p0 - excluded;
  json j = t.toJson(period);
  j["levels"] = layout.numLevels();
  j["partitions"] = layout.totalPartitions();
  j["swaps"] = swaps;
  j["ir_sets_allocated"] = pool.allocated();
  j["prepare_ms_median"] = 1e3 * percentile(pool.prepareSeconds(), 0.5);
  return j;
}

/// The uniform convolver (one per source, mixed into the bus), no swaps.
json runUniform(const CaseData& d, bool measure, double period) {
  using namespace dpc::audio;
  ConvolverLayout layout(
      d.block, d.irSamples,
      measure ? ConvolverLayout::Planning::kMeasure : ConvolverLayout::Planning::kEstimate);
  std::vector<std::unique_ptr<IrSpectra>> irs;
  std::vector<std::unique_ptr<PartitionedConvolver>> convs;
  for (int s = 0; s < d.sources; ++s) {
    irs.push_back(std::make_unique<IrSpectra>(layout, d.channels));
    std::vector<const float*> ch;
    for (int c = 0; c < d.channels; ++c) ch.push_back(d.irs[0][size_t(s * d.channels + c)].data());
    irs.back()->prepare(ch.data(), d.irSamples);
    convs.push_back(std::make_unique<PartitionedConvolver>(layout, d.channels));
    convs.back()->setNextIr(irs.back().get());
  }
  std::vector<std::vector<float>> out(size_t(d.channels), std::vector<float>(size_t(d.block)));
  std::vector<float*> outPtr;
  for (auto& o : out) outPtr.push_back(o.data());
  Timing t;
  const double p0 = processCpuSeconds();
  for (size_t k = 0; k < d.blocks; ++k) {
    const double t0 = threadCpuSeconds();
    for (auto& o : out) std::fill(o.begin(), o.end(), 0.0f);
    for (int s = 0; s < d.sources; ++s)
      convs[size_t(s)]->processAdd(d.input[size_t(s)].data() + k * size_t(d.block), outPtr.data());
    t.blockSeconds.push_back(threadCpuSeconds() - t0);
  }
  t.processSeconds = processCpuSeconds() - p0;
  return t.toJson(period);
}

#ifdef DPC_HAVE_ZITA
/// zita-convolver: quantum = minimum partition = block, maximum partition 8192 (as dpc),
/// every source to every output, worker threads at SCHED_OTHER like the benchmark thread.
json runZita(const CaseData& d, bool measure, std::vector<float>* firstOut, double period) {
  Convproc conv;
  if (measure) conv.set_options(Convproc::OPT_FFTW_MEASURE);
  if (conv.configure(uint32_t(d.sources), uint32_t(d.channels), uint32_t(d.irSamples),
                     uint32_t(d.block), uint32_t(d.block), Convproc::MAXPART, 1.0f))
    return {{"error", "configure failed"}};
  for (int s = 0; s < d.sources; ++s)
    for (int c = 0; c < d.channels; ++c)
      conv.impdata_create(uint32_t(s), uint32_t(c), 1,
                          const_cast<float*>(d.irs[0][size_t(s * d.channels + c)].data()), 0,
                          int32_t(d.irSamples));
  if (conv.start_process(0, SCHED_OTHER)) return {{"error", "start_process failed"}};
  if (firstOut) firstOut->clear();
  Timing t;
  uint64_t lateFlags = 0;
  const double p0 = processCpuSeconds();
  for (size_t k = 0; k < d.blocks; ++k) {
    const double t0 = threadCpuSeconds();
    for (int s = 0; s < d.sources; ++s)
      std::copy_n(d.input[size_t(s)].data() + k * size_t(d.block), d.block,
                  conv.inpdata(uint32_t(s)));
    if (conv.process(true) & Convproc::FL_LATE) ++lateFlags;
    t.blockSeconds.push_back(threadCpuSeconds() - t0);
    if (firstOut) firstOut->insert(firstOut->end(), conv.outdata(0), conv.outdata(0) + d.block);
  }
  t.processSeconds = processCpuSeconds() - p0;
  conv.stop_process();
  while (!conv.check_stop()) {
    timespec ts{0, 1000000};
    nanosleep(&ts, nullptr);
  }
  conv.cleanup();
  json j = t.toJson(period);
  j["late_blocks"] = lateFlags;
  return j;
}
#endif

/// 10 log10 of sum (a - b)^2 / sum b^2 over the second half of the run (how far dpc's output is
/// from zita's once dpc's first IR has faded in at every partition level).
double relativeErrorDb(const std::vector<float>& a, const std::vector<float>& b) {
  double err = 0.0, energy = 0.0;
  const size_t end = std::min(a.size(), b.size());
  for (size_t n = end / 2; n < end; ++n) {
    err += (double(a[n]) - b[n]) * (double(a[n]) - b[n]);
    energy += double(b[n]) * b[n];
  }
  return 10.0 * std::log10(std::max(err, 1e-300) / std::max(energy, 1e-300));
}

/// The report's two entries of one case at one block size: without and with IR swaps, each
/// against zita-convolver and the uniform convolver.
void runCase(const Case& cs, int block, const ConvolveOptions& o, json& list) {
  const double period = double(block) / o.sampleRate;
  const int swapEvery = std::max(1, int(std::lround(o.swapIntervalMs * 1e-3 / period)));
  const CaseData d = makeData(cs, block, o);
  std::vector<float> dpcOut, zitaOut;
  json zita = nullptr;
#ifdef DPC_HAVE_ZITA
  zita = runZita(d, false, &zitaOut, period);
#endif
  json uniform = o.uniform ? runUniform(d, false, period) : json(nullptr);
  for (int swapping = 0; swapping < 2; ++swapping) {
    json c;
    c["name"] = cs.name;
    c["id"] = cs.id;
    c["onset_max_seconds"] = cs.onsetMaxSeconds;
    c["block"] = block;
    c["sources"] = cs.sources;
    c["channels"] = cs.channels;
    c["ir_seconds"] = cs.irSeconds;
    c["swap_interval_ms"] = swapping ? 1e3 * swapEvery * period : 0.0;
    c["dpc"] =
        runNonUniform(d, swapping ? swapEvery : 0, false, swapping ? nullptr : &dpcOut, period);
    c["zita"] = zita;
    c["dpc_uniform_no_swap"] = uniform;
    if (zita.is_object() && zita.contains("cpu_percent_mean")) {
      c["ratio_to_zita"] =
          c["dpc"]["cpu_percent_mean"].get<double>() / zita["cpu_percent_mean"].get<double>();
      if (!swapping) c["dpc_vs_zita_output_error_db"] = relativeErrorDb(dpcOut, zitaOut);
    }
    std::fprintf(stderr, "convolve: block %d %s swap %d: dpc %.2f %% zita %s %%\n", block, cs.name,
                 swapping, c["dpc"]["cpu_percent_mean"].get<double>(),
                 zita.is_object() ? zita["cpu_percent_mean"].dump().c_str() : "-");
    list.push_back(c);
  }
}

}  // namespace

int benchConvolve(const ConvolveOptions& o) {
  // hybrid64: the market's hybrid rendering per source (64 mono early parts of 0.228 s, each
  // from its direct sound's delay, 3 to 117 ms); late4: its four late buses of 2 s.
  const Case cases[] = {{"mono", "mono 2 s", 1, 1, 2.0},
                        {"stereo", "stereo 2 s", 1, 2, 2.0},
                        {"2x3", "2 sources x 3 s", 2, 2, 3.0},
                        {"16x2", "16 sources x 2 s", 16, 2, 2.0},
                        {"hybrid64", "64 early parts x 0.228 s", 64, 1, 0.228, 0.12},
                        {"late4", "4 late buses x 2 s", 4, 1, 2.0}};
  json out;
  out["benchmark"] = "convolve";
  out["sample_rate"] = o.sampleRate;
  out["overlap"] = o.overlap;
  out["seconds_per_run"] = o.seconds;
  out["note"] =
      "CPU time of all threads (getrusage) over each run, as percent of one core's real time; "
      "per-block figures are the calling thread's. One process, runs in sequence: compare "
      "ratios, not absolute numbers, on a loaded machine.";
#ifdef DPC_HAVE_ZITA
  out["zita_version"] = std::to_string(ZITA_CONVOLVER_MAJOR_VERSION) + "." +
                        std::to_string(ZITA_CONVOLVER_MINOR_VERSION);
#else
  out["zita_version"] = nullptr;
#endif
  json list = json::array();
  for (int block : o.blocks)
    for (const Case& cs : cases)
      if (o.cases.empty() ||
          std::find(o.cases.begin(), o.cases.end(), std::string(cs.id)) != o.cases.end())
        runCase(cs, block, o, list);
  out["cases"] = list;
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

}  // namespace dpc::bench
