// Independent late fields from one set of Dirac sequences: a circular shift of the late part.
//
// A spatial synthesiser pre-convolves one Dirac sequence per direction with its band and
// channel filters (synthesis/spatial_synthesizer.h); every source it renders reads those same
// band signals, so without more, two sources in one room would get the same late noise and
// their reverberation would add coherently. Once the sequence's density has reached
// kIndependentFromDensity, its statistics change slowly along time, so a source can read the
// late part [start, start + span) circularly shifted by its own number of synthesis bins: the
// noise it hears there is a different stretch of the same stationary process, uncorrelated
// with every other source's at a shift of one 63 Hz synthesis bin (32 ms at 48 kHz) or more,
// far beyond the band filters' memory from 250 Hz up. The envelope gains are set from the
// rotated sequence's own pulse energies (BandEnvelope::rotate), so the levels stay exact. The
// stretch before `start` (first arrivals, sparse pulses) is shared: shifting it would move the
// sparse early pulses into the dense late part.
//
// All three numbers are multiples of the longest synthesis bin (BandEnvelope::binSamplesFor
// band 0), which every band's bin divides, so whole bins map onto whole bins in every band.
#pragma once

#include <cstddef>
#include <algorithm>
#include <numeric>

namespace dpc {

/// Pulses per second per direction from which a sequence is shifted per source. With the
/// K >= 8 directions the synthesiser sums, the ear hears >= 8000 pulses/s where a shifted
/// stretch starts, above the density (about 2000/s) at which a decay is heard as smooth
/// noise rather than as echoes (e.g. Karjalainen and Järveläinen, "More about this
/// reverberation science: perceptually good late reverberation", AES 111th Convention, 2001).
inline constexpr double kIndependentFromDensity = 1000.0;

struct LateRotation {
  size_t start = 0;  ///< first shifted sample
  size_t span = 0;   ///< shifted samples; 0: no shift
  size_t shift = 0;  ///< samples, < span

  /// The sample of the shared band signals that output sample n reads.
  size_t source(size_t n) const {
    if (span == 0 || n < start || n >= start + span) return n;
    const size_t k = n - start + shift;
    return start + (k >= span ? k - span : k);
  }

  /// Late field `field` (0: unshifted; a source's or a late bus's index) for signals of
  /// `length` samples shifted from sample `from` on, in whole bins of `bin` samples. The
  /// shifts step by about 0.38 of the span (a golden-ratio stride, coprime with the span's
  /// bins), so fields up to the span's bin count get distinct shifts and nearby fields far
  /// apart ones; fields repeat after that count. No allocation; any thread.
  static LateRotation forField(size_t field, size_t from, size_t length, size_t bin) {
    if (field == 0 || bin == 0) return {};
    const size_t start = (from + bin - 1) / bin * bin;
    if (start >= length) return {};
    const size_t bins = (length - start) / bin;
    if (bins < 2) return {};
    size_t stride = std::max<size_t>(1, size_t(double(bins) * 0.381966 + 0.5));
    while (std::gcd(stride, bins) != 1) ++stride;
    const size_t shiftBins = (field % bins) * stride % bins;
    return {start, bins * bin, shiftBins * bin};
  }
};

}  // namespace dpc
