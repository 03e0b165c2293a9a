#include "bench/noise_study.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/simulation.h"

namespace dpc {

namespace {

size_t rebinFactor() {
  return size_t(std::lround(kNoiseBinSeconds / Simulation::kEnergyBinSeconds));
}

double squaredNorm(const EnergyResponse& e) {
  double s = 0.0;
  for (const Bands& b : e.bins())
    for (int i = 0; i < kNumBands; ++i) s += double(b[i]) * b[i];
  return s;
}

double squaredDistance(const EnergyResponse& a, const EnergyResponse& b) {
  double s = 0.0;
  for (size_t k = 0; k < a.binCount(); ++k)
    for (int i = 0; i < kNumBands; ++i) {
      const double d = double(a.bins()[k][i]) - double(b.bins()[k][i]);
      s += d * d;
    }
  return s;
}

/// Sum of every bin and band of e.
double totalEnergy(const EnergyResponse& e) {
  double total = 0.0;
  for (const Bands& b : e.bins())
    for (int i = 0; i < kNumBands; ++i) total += double(b[i]);
  return total;
}

/// Whether bin k of e starts in the delay range [first, second) seconds.
bool binInRange(const EnergyResponse& e, size_t k, const std::pair<double, double>& range) {
  const double t = double(k) * e.binSeconds();
  return !(t < range.first || t >= range.second);
}

/// Standard error of the mean `mean` of the responses `all`, relative to its norm, over the
/// bins in `range`; 0 if the mean has no energy there.
double selfErrorInRange(const EnergyResponse& mean, const std::vector<EnergyResponse>& all,
                        const std::pair<double, double>& range) {
  const int frames = int(all.size());
  double spread = 0.0, norm = 0.0;
  for (size_t k = 0; k < mean.binCount(); ++k) {
    if (!binInRange(mean, k, range)) continue;
    for (int i = 0; i < kNumBands; ++i) {
      const double m = mean.bins()[k][i];
      norm += m * m;
      for (const EnergyResponse& e : all) {
        const double d = double(e.bins()[k][i]) - m;
        spread += d * d;
      }
    }
  }
  spread /= std::max(1, frames - 1);
  return norm > 0.0 ? std::sqrt(spread / frames / norm) : 0.0;
}

/// ||e - ref|| / ||ref|| over the bins in `range`; 0 if ref has no energy there.
double relativeErrorInRange(const EnergyResponse& e, const EnergyResponse& ref,
                            const std::pair<double, double>& range) {
  double d2 = 0.0, n2 = 0.0;
  for (size_t k = 0; k < e.binCount(); ++k) {
    if (!binInRange(e, k, range)) continue;
    for (int i = 0; i < kNumBands; ++i) {
      const double x = ref.bins()[k][i], d = double(e.bins()[k][i]) - x;
      d2 += d * d;
      n2 += x * x;
    }
  }
  return n2 > 0.0 ? std::sqrt(d2 / n2) : 0.0;
}

}  // namespace

EnergyResponse noiseBins(const EnergyResponse& e) {
  return e.rebinned(rebinFactor());
}

double relativeError(const EnergyResponse& e, const EnergyResponse& ref) {
  return std::sqrt(squaredDistance(e, ref) / squaredNorm(ref));
}

EnergyResponse referenceResponse(const SceneDesc& scene, PropagationSettings settings,
                                 const glm::vec3& listener, int frames, double* selfError,
                                 size_t source,
                                 const std::vector<std::pair<double, double>>* ranges,
                                 std::vector<double>* selfErrorByRange) {
  settings.estimator = Estimator::kPathTracing;
  Simulation sim(scene, settings);
  const size_t factor = rebinFactor();
  std::vector<EnergyResponse> all;
  EnergyResponse mean;
  for (int f = 0; f < frames; ++f) {
    sim.runFrame(listener);
    all.push_back(sim.result(source).energy.rebinned(factor));
    if (f == 0)
      mean = all.back();
    else
      for (size_t k = 0; k < mean.binCount(); ++k) mean.bins()[k] += all.back().bins()[k];
  }
  for (Bands& b : mean.bins()) b /= float(frames);
  if (selfError) {
    // Standard error of the mean from the spread of the frames.
    double spread = 0.0;
    for (const EnergyResponse& e : all) spread += squaredDistance(e, mean);
    spread /= std::max(1, frames - 1);
    *selfError = std::sqrt(spread / frames / squaredNorm(mean));
  }
  if (ranges && selfErrorByRange) {
    selfErrorByRange->assign(ranges->size(), 0.0);
    for (size_t r = 0; r < ranges->size(); ++r)
      (*selfErrorByRange)[r] = selfErrorInRange(mean, all, (*ranges)[r]);
  }
  return mean;
}

NoiseMetrics measureNoise(const SceneDesc& scene, const PropagationSettings& settings, int warmup,
                          int frames, const std::function<glm::vec3(int)>& listenerAt,
                          const std::function<const EnergyResponse&(int)>& referenceAt,
                          size_t source, const std::function<glm::vec3(int)>& sourceAt,
                          const std::vector<std::pair<double, double>>& ranges) {
  Simulation sim(scene, settings);
  std::vector<glm::vec3> sources;
  for (const SourceDesc& s : scene.sources) sources.push_back(s.position);
  const size_t factor = rebinFactor();
  NoiseMetrics m;
  EnergyResponse previous, sum;
  for (int f = 0; f < warmup + frames; ++f) {
    if (sourceAt) sources[source] = sourceAt(f);
    sim.runFrame(listenerAt(f), sources);
    EnergyResponse e = sim.result(source).energy.rebinned(factor);
    const EnergyResponse& ref = referenceAt(f);
    const double refNorm = std::sqrt(squaredNorm(ref));
    const double err = std::sqrt(squaredDistance(e, ref)) / refNorm;
    m.errorPerFrame.push_back(err);
    m.energyPerFrame.push_back(totalEnergy(e));
    if (f >= warmup && !ranges.empty()) {
      m.errorByRange.resize(ranges.size(), 0.0);
      for (size_t r = 0; r < ranges.size(); ++r)
        m.errorByRange[r] += relativeErrorInRange(e, ref, ranges[r]) / frames;
    }
    if (f >= warmup) {
      m.meanError += err;
      if (f > 0) m.meanFlicker += std::sqrt(squaredDistance(e, previous)) / refNorm;
      if (f == warmup)
        sum = e;
      else
        for (size_t k = 0; k < sum.binCount(); ++k) sum.bins()[k] += e.bins()[k];
    }
    previous = std::move(e);
  }
  m.frames = frames;
  m.meanError /= frames;
  m.meanFlicker /= frames;
  // Bias against the reference of the last frame (meaningful for a static listener).
  for (Bands& b : sum.bins()) b /= float(frames);
  const EnergyResponse& ref = referenceAt(warmup + frames - 1);
  m.bias = std::sqrt(squaredDistance(sum, ref) / squaredNorm(ref));
  m.energyBias = double(sum.total().sum()) / double(ref.total().sum()) - 1.0;
  return m;
}

std::pair<double, double> delayRangeOfOrders(int d0, int d1, double volume, double surfaceArea,
                                             double c, double directDelay) {
  const double perOrder = 4.0 * volume / (c * surfaceArea);
  return {directDelay + (double(d0) - 0.5) * perOrder, directDelay + (double(d1) + 0.5) * perOrder};
}

std::vector<double> cacheAveraged(const std::vector<double>& perFrame, DpcWeighting weighting,
                                  double tau, double frameRate) {
  std::vector<double> out(perFrame.size(), 0.0);
  if (weighting == DpcWeighting::kWindow) {
    const size_t w = size_t(std::max(1L, std::lround(tau * frameRate)));
    for (size_t f = 0; f < perFrame.size(); ++f) {
      const size_t n = std::min(f + 1, w);
      for (size_t k = f + 1 - n; k <= f; ++k) out[f] += perFrame[k] / double(n);
    }
  } else if (weighting == DpcWeighting::kEma) {
    const double a = tau > 0.0 ? 1.0 - std::exp(-1.0 / (tau * frameRate)) : 1.0;
    double ema = 0.0, decay = 1.0;
    for (size_t f = 0; f < perFrame.size(); ++f) {
      ema = (1.0 - a) * ema + a * perFrame[f];
      decay *= 1.0 - a;
      out[f] = ema / (1.0 - decay);
    }
  } else {
    throw std::invalid_argument("cacheAveraged: the seed weighting has no unbiased average");
  }
  return out;
}

}  // namespace dpc
