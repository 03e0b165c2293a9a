#include "wave/wave_join.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/butterworth.h"

namespace dpc::wave {

std::vector<int> simulatedBands(double crossoverHz) {
  std::vector<int> bands{0};
  for (int b = 1; b < kNumBands && kBandCentreHz[size_t(b)] <= crossoverHz; ++b) bands.push_back(b);
  return bands;
}

std::vector<double> bandEdges(std::span<const int> bands) {
  std::vector<double> edges;
  for (size_t k = 1; k < bands.size(); ++k)
    edges.push_back(std::sqrt(bandCentreExactHz(bands[k - 1]) * bandCentreExactHz(bands[k])));
  return edges;
}

void splitBand(std::span<float> x, size_t k, std::span<const double> edges, double fs) {
  using Kind = Butterworth::Kind;
  for (size_t e = 0; e < edges.size(); ++e) {
    const Kind kind = e < k ? Kind::kHighPass : e == k ? Kind::kLowPass : Kind::kSumAllPass;
    Butterworth::design(kind, kCrossoverOrder, edges[e], fs).run(x);
  }
}

double waveBandGain(OutputFormat format, int channel, int channels) {
  switch (format) {
    case OutputFormat::kMono:
    case OutputFormat::kBinaural:
      return 1.0;
    case OutputFormat::kAmbisonics:
    case OutputFormat::kAmbisonicBinaural:  // its IRs are AmbiX, decoded per block
      return channel == 0 ? 1.0 : 0.0;
    case OutputFormat::kStereo:
    case OutputFormat::kLoudspeakers:
      return 1.0 / std::sqrt(double(std::max(channels, 1)));
  }
  return 0.0;
}

namespace {

using K = Butterworth::Kind;

std::vector<Butterworth> edgeAllPasses(double crossoverHz, double fs) {
  std::vector<Butterworth> out;
  for (double e : bandEdges(simulatedBands(crossoverHz)))
    out.push_back(Butterworth::design(K::kSumAllPass, kCrossoverOrder, e, fs));
  return out;
}

/// `ray` through the allpasses and the high-pass in place, plus gain times `lowPassed` (the
/// wave band already through P and the low-pass).
void addToHighPassed(std::span<float> ray, std::span<const float> lowPassed, double gain,
                     std::span<const Butterworth> allPasses, const Butterworth& highPass) {
  for (const Butterworth& a : allPasses) a.run(ray);
  highPass.run(ray);
  const size_t n = std::min(ray.size(), lowPassed.size());
  for (size_t i = 0; i < n; ++i) ray[i] += float(gain * double(lowPassed[i]));
}

/// The wave band through P (maxFrequencyHz) and the crossover's low-pass, in place.
void lowPass(std::span<float> band, double crossoverHz, double maxFrequencyHz, double fs) {
  Butterworth::design(K::kLowPass, kPulseOrder, maxFrequencyHz, fs).run(band);
  Butterworth::design(K::kLowPass, kCrossoverOrder, crossoverHz, fs).run(band);
}

}  // namespace

WaveBandSet::WaveBandSet(size_t listeners, size_t sources, OutputFormat format,
                         double crossoverHz, double maxFrequencyHz, double fs)
    : sources_(sources),
      format_(format),
      crossoverHz_(crossoverHz),
      maxFrequencyHz_(maxFrequencyHz),
      fs_(fs),
      highPass_(Butterworth::design(K::kHighPass, kCrossoverOrder, crossoverHz, fs)),
      allPass_(Butterworth::design(K::kAllPass, kPulseOrder, maxFrequencyHz, fs)),
      edgeAllPasses_(edgeAllPasses(crossoverHz, fs)),
      lowPassed_(listeners * sources) {
  edgeAllPasses_.push_back(allPass_);
}

void WaveBandSet::set(size_t listener, size_t source, std::span<const float> band) {
  std::vector<float>& low = lowPassed_.at(listener * sources_ + source);
  low.assign(band.begin(), band.end());
  lowPass(low, crossoverHz_, maxFrequencyHz_, fs_);
}

bool WaveBandSet::has(size_t listener, size_t source) const {
  const size_t k = listener * sources_ + source;
  return k < lowPassed_.size() && !lowPassed_[k].empty();
}

void WaveBandSet::join(size_t listener, size_t source, ImpulseResponse& ir) const {
  const std::vector<float>& low = lowPassed_.at(listener * sources_ + source);
  for (int c = 0; c < ir.channels(); ++c)
    addToHighPassed(ir.channelSpan(c), low, waveBandGain(format_, c, ir.channels()),
                    edgeAllPasses_, highPass_);
}

void WaveBandSet::join(std::span<const BandWeight> blend, size_t source,
                       ImpulseResponse& ir) const {
  for (int c = 0; c < ir.channels(); ++c) {
    const std::span<float> ray = ir.channelSpan(c);
    addToHighPassed(ray, {}, 0.0, edgeAllPasses_, highPass_);
    const double gain = waveBandGain(format_, c, ir.channels());
    for (const BandWeight& b : blend) {
      if (!has(b.listener, source)) continue;
      const std::vector<float>& low = lowPassed_[b.listener * sources_ + source];
      const double g = gain * double(b.weight);
      const size_t n = std::min(ray.size(), low.size());
      for (size_t i = 0; i < n; ++i) ray[i] += float(g * double(low[i]));
    }
  }
}

void joinWaveBand(std::span<float> rayChannel, std::span<const float> wave, double gain,
                  double crossoverHz, double maxFrequencyHz, double fs) {
  std::vector<float> low(rayChannel.size(), 0.f);
  std::copy_n(wave.begin(), std::min(wave.size(), low.size()), low.begin());
  lowPass(low, crossoverHz, maxFrequencyHz, fs);
  std::vector<Butterworth> allPasses = edgeAllPasses(crossoverHz, fs);
  allPasses.push_back(Butterworth::design(K::kAllPass, kPulseOrder, maxFrequencyHz, fs));
  addToHighPassed(rayChannel, low, gain, allPasses,
                  Butterworth::design(K::kHighPass, kCrossoverOrder, crossoverHz, fs));
}

}  // namespace dpc::wave
