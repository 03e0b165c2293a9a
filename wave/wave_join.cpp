#include "wave/wave_join.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/butterworth.h"

namespace dpc::wave {

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

/// `ray` through the allpass and the high-pass in place, plus gain times `lowPassed` (the wave
/// band already through P and the low-pass).
void addToHighPassed(std::span<float> ray, std::span<const float> lowPassed, double gain,
                     const Butterworth& allPass, const Butterworth& highPass) {
  allPass.run(ray);
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
      lowPassed_(listeners * sources) {}

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
    addToHighPassed(ir.channelSpan(c), low, waveBandGain(format_, c, ir.channels()), allPass_,
                    highPass_);
}

void joinWaveBand(std::span<float> rayChannel, std::span<const float> wave, double gain,
                  double crossoverHz, double maxFrequencyHz, double fs) {
  std::vector<float> low(rayChannel.size(), 0.f);
  std::copy_n(wave.begin(), std::min(wave.size(), low.size()), low.begin());
  lowPass(low, crossoverHz, maxFrequencyHz, fs);
  addToHighPassed(rayChannel, low, gain, Butterworth::design(K::kAllPass, kPulseOrder, maxFrequencyHz, fs),
                  Butterworth::design(K::kHighPass, kCrossoverOrder, crossoverHz, fs));
}

}  // namespace dpc::wave
