#include "synthesis/mono_synthesizer.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "common/durations.h"
#include "common/fftw_util.h"
#include "synthesis/arrival_placer.h"
#include "synthesis/band_envelope.h"
#include "synthesis/band_leveller.h"
#include "synthesis/band_tilt.h"
#include "synthesis/dirac_sequence.h"
#include "synthesis/window_leveller.h"

namespace dpc {

IrSynthesizer::~IrSynthesizer() = default;
IrSynthesizer::IrSynthesizer(IrSynthesizer&&) noexcept = default;
IrSynthesizer& IrSynthesizer::operator=(IrSynthesizer&&) noexcept = default;

IrSynthesizer::IrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume,
                             double speedOfSound, uint64_t seed, const IrSynthesizer* shareWith,
                             Build build)
    : sampleRate_(sampleRate) {
  if (sampleRate <= 0 || !(lengthSeconds > 0.0) || !(roomVolume > 0.0) || !(speedOfSound > 0.0) ||
      !std::isfinite(lengthSeconds) || !std::isfinite(roomVolume) || !std::isfinite(speedOfSound))
    throw std::invalid_argument("IrSynthesizer: rate, length, volume and c must be finite, > 0");
  length_ = stepsCovering(lengthSeconds, 1.0 / sampleRate);
  const size_t margin = bandFilterTaps(sampleRate);
  FftwRealTransforms fft(bandFftSize());
  std::vector<float> seq =
      diracSequence(sampleRate, length_, roomVolume, speedOfSound, kMaxPulseDensity, seed);
  std::fill(fft.time.p, fft.time.p + fft.n, 0.f);
  std::copy(seq.begin(), seq.end(), fft.time.p);
  fftwf_execute(fft.fwd);
  const bool share = sharesWith(shareWith);
  masks_ = share ? shareWith->masks_ : std::make_shared<const OctaveBandMasks>(sampleRate, fft.n);
  const OctaveBandMasks& masks = *masks_;
  filterData_ = share ? shareWith->filterData_ : BandFilterData::compute(masks, fft.n);
  bands_ = std::make_unique<TiltedBands>(
      sampleRate, length_, seq, masks, fft, shareWith ? shareWith->bands_.get() : nullptr,
      build == Build::kComplete ? TiltedBands::Levelling::kAtConstruction
                                : TiltedBands::Levelling::kDeferred);
  if (share) {
    direct_ = shareWith->direct_;
    leveller_ = shareWith->leveller_;
    placer_ = shareWith->placer_;
  } else {
    direct_ = std::make_shared<const DirectSoundFilter>(masks, fft, margin);
    placer_ = std::make_shared<ArrivalPlacer>(masks, direct_, fft.n);
    leveller_ = std::make_shared<BandLeveller>(
        sampleRate, length_, kFirstCleanedBand,
        BandLeveller::densityStart(sampleRate, roomVolume, speedOfSound, 10.0));
  }
  envelope_ = std::make_unique<BandEnvelope>(
      sampleRate, seq, length_, filterData_,
      measureLowBands(fft, masks, length_, TiltedBands::kLevelledFromBand));
  arrivals_.reserve(kReservedArrivals);
  if (build == Build::kComplete)
    takeWindowLeveller(shareWith);
  else
    sequence_ = std::move(seq);
}

IrSynthesizer::Workspace IrSynthesizer::workspace() const {
  return {placer_, leveller_, windowLeveller_, bands_->scratch()};
}

void IrSynthesizer::useWorkspace(const Workspace& w) {
  placer_ = w.placer;
  leveller_ = w.leveller;
  windowLeveller_ = w.windowLeveller;
  bands_->useScratch(w.tilted);
}

size_t IrSynthesizer::bandFftSize() const {
  return smoothFftSize(length_ + bandFilterTaps(sampleRate_));
}

void IrSynthesizer::takeWindowLeveller(const IrSynthesizer* shareWith) {
  windowLeveller_ = sharesWith(shareWith) && shareWith->windowLeveller_
                        ? shareWith->windowLeveller_
                        : std::make_shared<WindowLeveller>(sampleRate_, length_, kFirstLevelledBand,
                                                           kLastLevelledBand);
}

bool IrSynthesizer::completed() const {
  return bands_->levelled();
}

void IrSynthesizer::complete(const IrSynthesizer* shareWith) {
  if (completed()) return;
  FftwRealTransforms fft(bandFftSize());
  bands_->level(sequence_, fft);
  takeWindowLeveller(shareWith);
  sequence_ = std::vector<float>();
}

void IrSynthesizer::synthesize(const EnergyResponse& energy, const DirectSound& direct, float* ir,
                               std::span<const SpecularPath> early) {
  std::fill(ir, ir + length_, 0.f);
  arrivals_.clear();
  if (direct.visible) arrivals_.push_back({double(direct.delaySeconds), direct.intensity});
  for (const SpecularPath& p : early) arrivals_.push_back({p.delaySeconds, p.intensity});
  mergeCoincidentArrivals(arrivals_, sampleRate_);
  bands_->update(energy);
  envelope_->compute(energy);
  std::array<const float*, kNumBands> tilted;
  for (int b = 0; b < kNumBands; ++b) tilted[size_t(b)] = bands_->tilted(b).data();
  const size_t onset = firstArrivalSample(energy);
  envelope_->startAt(onset, tilted);
  envelope_->accumulateRange(tilted, ir, onset, length_);
  if (windowLeveller_ && !arrivals_.empty()) {
    // The deterministic part (direct sound, exact paths) placed apart, so that the levelling
    // sees what it adds to each window and levels the whole IR's energy there; the noise
    // cleared around them before (what the levelling measures) and after (its correction).
    float* fixed = windowLeveller_->fixedScratch();
    std::fill(fixed, fixed + length_, 0.f);
    placer_->place(arrivals_, sampleRate_, fixed, length_);
    clearAroundArrivals(ir);
    windowLeveller_->level(energy, onset, ir, fixed);
    clearAroundArrivals(ir);
    for (size_t n = 0; n < length_; ++n) ir[n] += fixed[n];
  } else {
    if (windowLeveller_) windowLeveller_->level(energy, onset, ir);
    clearAroundArrivals(ir);
    placer_->place(arrivals_, sampleRate_, ir, length_);
  }
  cleanUp(energy, ir);
  float* const channels[] = {ir};
  cutLeadingResidue(channels, length_, onset, sampleRate_);
  // The envelope's unplaced energy is as a band measurement sees it (E_b beta_b).
  for (int b = 0; b < kNumBands; ++b)
    missingBands_[b] = float(envelope_->unplacedEnergy()[size_t(b)] / filterData_.share[size_t(b)]);
}

size_t IrSynthesizer::firstArrivalSample(const EnergyResponse& energy) const {
  double t = energy.binCount() * energy.binSeconds();
  for (const Arrival& a : arrivals_) t = std::min(t, a.delaySeconds);
  for (size_t k = 0; k < energy.binCount() && double(k) * energy.binSeconds() < t; ++k) {
    const Bands& e = energy.bins()[k];
    if (e.max() > 0.f) {
      t = double(k) * energy.binSeconds();
      break;
    }
  }
  return std::min(length_, size_t(std::max(0L, std::lround(t * sampleRate_))));
}

void IrSynthesizer::clearAroundArrivals(float* ir) const {
  for (const Arrival& a : arrivals_) {
    const long n0 = std::lround(a.delaySeconds * sampleRate_);
    for (long n = std::max(0L, n0 - kClearSamples); n <= n0 + kClearSamples; ++n)
      if (n < long(length_)) ir[n] = 0.f;
  }
}

void IrSynthesizer::cleanUp(const EnergyResponse& energy, float* ir) {
  leveller_->clearTargets();
  leveller_->addResponse(energy, Bands(1.f));
  for (const Arrival& a : arrivals_) leveller_->addDirect(a.delaySeconds, a.intensity);
  std::array<BandLeveller::Levelling, kNumBands> perBand;
  for (int b = 0; b < kNumBands; ++b)
    perBand[size_t(b)] = b <= kLastTwoWayBand ? BandLeveller::Levelling{1.0, kTwoWayBoost}
                                              : BandLeveller::Levelling{kCleanMargin, 1.0};
  leveller_->apply(ir, perBand);
}

}  // namespace dpc
