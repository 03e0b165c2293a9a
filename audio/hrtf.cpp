// Hrtf: libmysofa loading, frontal normalisation and the direction grid (see hrtf.h).
#include "audio/hrtf.h"

#include <mysofa.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "common/input_error.h"

namespace dpc::audio {

namespace {

constexpr int kAzimuthSteps = int(360.0f / Hrtf::kGridStepDegrees);        // 72 columns
constexpr int kElevationSteps = int(180.0f / Hrtf::kGridStepDegrees) + 1;  // 37 rows, poles
constexpr float kRadToDeg = float(180.0 / std::numbers::pi);
constexpr float kDegToRad = float(std::numbers::pi / 180.0);
// Hz: the HRIR sets' sampling rates the resampler is given (those of the output, Hrtf::load).
constexpr int kMinSofaSampleRate = 8000, kMaxSofaSampleRate = 384000;

// libmysofa returns either one of its own codes (>= 10000, or -1) or an errno value from
// fopen (mysofa_load passes errno through).
std::string mysofaErrorText(int err) {
  switch (err) {
    case MYSOFA_INTERNAL_ERROR:
      return "libmysofa internal error (MYSOFA_INTERNAL_ERROR)";
    case MYSOFA_INVALID_FORMAT:
      return "not a valid SOFA file: libmysofa could not read it as HDF5 with SOFA conventions "
             "(MYSOFA_INVALID_FORMAT)";
    case MYSOFA_UNSUPPORTED_FORMAT:
      return "uses an HDF5/SOFA feature libmysofa does not support (MYSOFA_UNSUPPORTED_FORMAT)";
    case MYSOFA_NO_MEMORY:
      return "out of memory while reading (MYSOFA_NO_MEMORY)";
    case MYSOFA_READ_ERROR:
      return "read error (MYSOFA_READ_ERROR)";
    case MYSOFA_INVALID_ATTRIBUTES:
      return "missing or invalid SOFA attributes; expected convention SimpleFreeFieldHRIR "
             "(MYSOFA_INVALID_ATTRIBUTES)";
    case MYSOFA_INVALID_DIMENSIONS:
      return "invalid SOFA dimensions (MYSOFA_INVALID_DIMENSIONS)";
    case MYSOFA_INVALID_DIMENSION_LIST:
      return "invalid SOFA dimension list (MYSOFA_INVALID_DIMENSION_LIST)";
    case MYSOFA_INVALID_COORDINATE_TYPE:
      return "invalid coordinate type (MYSOFA_INVALID_COORDINATE_TYPE)";
    case MYSOFA_ONLY_EMITTER_WITH_ECI_SUPPORTED:
      return "only emitters with ECI dimensions are supported "
             "(MYSOFA_ONLY_EMITTER_WITH_ECI_SUPPORTED)";
    case MYSOFA_ONLY_DELAYS_WITH_IR_OR_MR_SUPPORTED:
      return "only Data.Delay with IR or MR dimensions is supported "
             "(MYSOFA_ONLY_DELAYS_WITH_IR_OR_MR_SUPPORTED)";
    case MYSOFA_ONLY_THE_SAME_SAMPLING_RATE_SUPPORTED:
      return "all measurements must share one sampling rate "
             "(MYSOFA_ONLY_THE_SAME_SAMPLING_RATE_SUPPORTED)";
    case MYSOFA_RECEIVERS_WITH_RCI_SUPPORTED:
      return "receivers must have RCI dimensions (MYSOFA_RECEIVERS_WITH_RCI_SUPPORTED)";
    case MYSOFA_RECEIVERS_WITH_CARTESIAN_SUPPORTED:
      return "receiver positions must be cartesian (MYSOFA_RECEIVERS_WITH_CARTESIAN_SUPPORTED)";
    case MYSOFA_INVALID_RECEIVER_POSITIONS:
      return "receivers must be two ears on the y axis (MYSOFA_INVALID_RECEIVER_POSITIONS)";
    case MYSOFA_ONLY_SOURCES_WITH_MC_SUPPORTED:
      return "source positions must have MC dimensions (MYSOFA_ONLY_SOURCES_WITH_MC_SUPPORTED)";
    default:
      break;
  }
  if (err > 0 && err < MYSOFA_INVALID_FORMAT)
    return std::string("cannot open: ") + std::strerror(err);
  return "libmysofa error code " + std::to_string(err);
}

struct EasyCloser {
  void operator()(MYSOFA_EASY* e) const { mysofa_close(e); }
};

/// Throws InputError(path, "Data.SamplingRate", ...) unless the file's sampling rate is one
/// the resampler takes: mysofa_open passes the resampler's own error codes (1, 3) on as if
/// they were errno values ("Operation not permitted", "No such process").
void checkSamplingRate(const std::string& path) {
  int err = 0;
  std::unique_ptr<MYSOFA_HRTF, decltype(&mysofa_free)> h(mysofa_load(path.c_str(), &err),
                                                          &mysofa_free);
  if (!h || err != MYSOFA_OK) throw InputError(path, "", mysofaErrorText(err));
  const MYSOFA_ARRAY& rate = h->DataSamplingRate;
  if (rate.elements < 1 || rate.values == nullptr)
    throw InputError(path, "Data.SamplingRate", "missing");
  const float hz = rate.values[0];
  if (!(hz >= float(kMinSofaSampleRate) && hz <= float(kMaxSofaSampleRate))) {
    char text[96];
    std::snprintf(text, sizeof text, "%g Hz is outside [%d, %d] Hz", double(hz),
                  kMinSofaSampleRate, kMaxSofaSampleRate);
    throw InputError(path, "Data.SamplingRate", text);
  }
}

// Direction -> (azimuth in [0, 360), elevation in [-90, 90]) degrees, SOFA convention.
// Zero or non-finite vectors map to straight ahead.
void toSpherical(const float d[3], float* azimuthDeg, float* elevationDeg) {
  const float x = d[0], y = d[1], z = d[2];
  const float r2 = x * x + y * y + z * z;
  if (!(r2 > 0.0f) || !std::isfinite(r2)) {
    *azimuthDeg = 0.0f;
    *elevationDeg = 0.0f;
    return;
  }
  float az = std::atan2(y, x) * kRadToDeg;
  if (az < 0.0f) az += 360.0f;
  if (az >= 360.0f) az -= 360.0f;
  *azimuthDeg = az;
  *elevationDeg = std::atan2(z, std::sqrt(x * x + y * y)) * kRadToDeg;
}

// Fills the direction grid from the (resampled) measurements of `h` (cartesian source
// positions, as mysofa_open leaves them). Each node blends the measurements around it with
// modified Shepard weights w_i = ((R - d_i)_+ / (R d_i))^2, d_i the chord distance between unit
// directions and R = d_min + min(2 d_min, chord(10 deg)) (d_min: distance to the nearest
// measurement); a node on a
// measurement copies it. The weights are continuous in the direction and use every measurement
// within R (no tie-breaking), so the table is continuous and, for a left/right symmetric set,
// exactly symmetric. (libmysofa 1.3's own interpolation, mysofa_getfilter_float, is neither:
// nearest measurement from a k-d tree plus the closer neighbour per axis, which jumps when the
// nearest measurement changes and breaks KEMAR's exact mirror symmetry; see hrtf_test.)
// Measurements at less than 99 % of the largest radius are ignored (direction only).
struct MeasuredDirection {
  float x, y, z;  ///< unit vector
  unsigned m;     ///< measurement index
};

// The measurements' unit directions, those at less than 99 % of the largest radius left out.
std::vector<MeasuredDirection> measuredDirections(const MYSOFA_HRTF& h) {
  std::vector<MeasuredDirection> dirs;
  float rMax = 0;
  for (unsigned m = 0; m < h.M; ++m) {
    const float* p = h.SourcePosition.values + size_t(m) * h.C;
    rMax = std::max(rMax, std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
  }
  for (unsigned m = 0; m < h.M; ++m) {
    const float* p = h.SourcePosition.values + size_t(m) * h.C;
    const float r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    if (r >= 0.99f * rMax && r > 0) dirs.push_back({p[0] / r, p[1] / r, p[2] / r, m});
  }
  return dirs;
}

// Measurement m's delay for one ear (per measurement, or one per receiver), samples.
float delayOf(const MYSOFA_HRTF& h, unsigned m, int ear) {
  if (h.DataDelay.elements == 0) return 0.0f;
  return h.DataDelay.elements >= h.M * h.R ? h.DataDelay.values[size_t(m) * h.R + size_t(ear)]
                                           : h.DataDelay.values[size_t(ear) % h.DataDelay.elements];
}

// One grid node: the Shepard blend (see fillGrid) of the measurements around unit direction u
// into out[0, 2n) ([left | right]) and delay[2]. dist and acc are scratch of dirs.size() and 2n.
void blendNode(const MYSOFA_HRTF& h, int n, const std::vector<MeasuredDirection>& dirs,
               const double u[3], std::vector<double>& dist, std::vector<double>& acc, float* out,
               float* delayOut) {
  double dMin = 1e9;
  size_t nearest = 0;
  for (size_t q = 0; q < dirs.size(); ++q) {
    const double dx = u[0] - dirs[q].x, dy = u[1] - dirs[q].y, dz = u[2] - dirs[q].z;
    dist[q] = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (dist[q] < dMin) dMin = dist[q], nearest = q;
  }
  std::fill(acc.begin(), acc.end(), 0.0);
  double delay[2] = {0, 0}, wSum = 0;
  auto add = [&](size_t q, double w) {
    const float* src = h.DataIR.values + size_t(dirs[q].m) * h.R * h.N;
    for (int k = 0; k < 2 * n; ++k) acc[size_t(k)] += w * src[k];  // [left | right]
    for (int ear = 0; ear < 2; ++ear) delay[ear] += w * delayOf(h, dirs[q].m, ear);
    wSum += w;
  };
  if (dMin < 1e-6) {
    add(nearest, 1.0);
  } else {
    // 3 d_min, but at most d_min + 10 degrees of arc, so that nodes far from any measurement
    // (below KEMAR's -40 degree ring) blend the nearest ring, not a hemisphere.
    const double radius = dMin + std::min(2.0 * dMin, 2.0 * std::sin(5.0 * std::numbers::pi / 180));
    for (size_t q = 0; q < dirs.size(); ++q)
      if (dist[q] < radius) {
        const double w = (radius - dist[q]) / (radius * dist[q]);
        add(q, w * w);
      }
  }
  for (int k = 0; k < 2 * n; ++k) out[k] = float(acc[size_t(k)] / wSum);
  delayOut[0] = float(delay[0] / wSum);
  delayOut[1] = float(delay[1] / wSum);
}

void fillGrid(const MYSOFA_HRTF& h, int n, const std::vector<MeasuredDirection>& dirs,
              std::vector<float>* irs, std::vector<float>* delays) {
  const int nodes = kAzimuthSteps * kElevationSteps;
  irs->assign(size_t(nodes) * 2 * size_t(n), 0.0f);
  delays->assign(size_t(nodes) * 2, 0.0f);
  std::vector<double> dist(dirs.size()), acc(size_t(2 * n));
  for (int i = 0; i < kElevationSteps; ++i) {
    const double el = (-90.0 + Hrtf::kGridStepDegrees * i) * std::numbers::pi / 180;
    for (int j = 0; j < kAzimuthSteps; ++j) {
      const double az = Hrtf::kGridStepDegrees * j * std::numbers::pi / 180;
      const double u[3] = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
      const size_t node = size_t(i) * kAzimuthSteps + size_t(j);
      blendNode(h, n, dirs, u, dist, acc, irs->data() + node * 2 * size_t(n),
                delays->data() + node * 2);
    }
  }
}

}  // namespace

struct Hrtf::Impl {
  std::unique_ptr<MYSOFA_EASY, EasyCloser> easy;
  std::mutex easyMutex;  // libmysofa's getfilter writes easy->fir: one caller at a time
  int sampleRate = 0;
  int n = 0;          // filter length, samples
  float gain = 1.0f;  // frontal normalisation, applied to every filter and both ears
  // Grid node (row i = elevation -90 + 5 i, column j = azimuth 5 j) at index i * 72 + j:
  // irs[(node * 2 + ear) * n ...], delays[node * 2 + ear].
  std::vector<float> irs;
  std::vector<float> delays;
  std::vector<MeasuredDirection> measured;  // the measurements the grid is filled from

  const float* ir(int node, int ear) const {
    return irs.data() + (size_t(node) * 2 + size_t(ear)) * size_t(n);
  }

  // Unlocked libmysofa call (caller holds easyMutex or owns the object exclusively).
  void exact(const float d[3], float* left, float* right, float* dl, float* dr) {
    float x = d[0], y = d[1], z = d[2];
    const float r2 = x * x + y * y + z * z;
    if (!(r2 > 0.0f) || !std::isfinite(r2)) x = 1.0f, y = 0.0f, z = 0.0f;
    mysofa_getfilter_float(easy.get(), x, y, z, left, right, dl, dr);
    for (int k = 0; k < n; ++k) {
      left[k] *= gain;
      right[k] *= gain;
    }
  }
};

Hrtf::Hrtf(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Hrtf::Hrtf(Hrtf&&) noexcept = default;
Hrtf& Hrtf::operator=(Hrtf&&) noexcept = default;
Hrtf::~Hrtf() = default;

Hrtf Hrtf::load(const std::string& path, int sampleRate) {
  if (sampleRate < kMinSofaSampleRate || sampleRate > kMaxSofaSampleRate)
    throw std::invalid_argument("Hrtf::load: sample rate " + std::to_string(sampleRate) +
                                " Hz is outside [8000, 384000]");
  checkSamplingRate(path);
  auto impl = std::make_unique<Impl>();
  int filterLength = 0, err = 0;
  impl->easy.reset(mysofa_open_no_norm(path.c_str(), float(sampleRate), &filterLength, &err));
  if (!impl->easy || err != MYSOFA_OK) throw InputError(path, "", mysofaErrorText(err));
  if (filterLength <= 0 || impl->easy->hrtf == nullptr || impl->easy->hrtf->R != 2)
    throw InputError(path, "", "not a two-ear HRIR set (SOFA dimension R must be 2)");
  impl->sampleRate = sampleRate;
  impl->n = filterLength;
  const int n = filterLength;

  // Direction grid, filled from the measurements (see fillGrid), then normalised so that the
  // frontal node has per-ear energy 1 (see hrtf.h).
  impl->measured = measuredDirections(*impl->easy->hrtf);
  fillGrid(*impl->easy->hrtf, n, impl->measured, &impl->irs, &impl->delays);
  {
    const int front = (kElevationSteps / 2) * kAzimuthSteps;  // azimuth 0, elevation 0
    double e = 0;
    for (int ear = 0; ear < 2; ++ear) {
      const float* x = impl->ir(front, ear);
      for (int k = 0; k < n; ++k) e += double(x[k]) * x[k];
    }
    if (!(e > 0) || !std::isfinite(e))
      throw InputError(path, "", "the frontal HRIR is silent or not finite; cannot normalise");
    impl->gain = float(std::sqrt(2.0 / e));
    for (float& v : impl->irs) v *= impl->gain;
  }
  for (float v : impl->irs)
    if (!std::isfinite(v)) throw InputError(path, "", "HRIRs contain non-finite samples");
  return Hrtf(std::move(impl));
}

int Hrtf::filterLength() const {
  return impl_->n;
}
int Hrtf::sampleRate() const {
  return impl_->sampleRate;
}

void Hrtf::hrir(const float direction[3], float* left, float* right, float* leftDelaySamples,
                float* rightDelaySamples) const {
  float az, el;
  toSpherical(direction, &az, &el);
  const float fi = (el + 90.0f) / kGridStepDegrees;  // [0, 36]
  const float fj = az / kGridStepDegrees;            // [0, 72)
  const int i0 = std::clamp(int(fi), 0, kElevationSteps - 2);
  const int j0 = std::clamp(int(fj), 0, kAzimuthSteps - 1);
  const float ti = std::clamp(fi - float(i0), 0.0f, 1.0f);
  const float tj = std::clamp(fj - float(j0), 0.0f, 1.0f);
  const int j1 = (j0 + 1) % kAzimuthSteps;
  const int node[4] = {i0 * kAzimuthSteps + j0, i0 * kAzimuthSteps + j1,
                       (i0 + 1) * kAzimuthSteps + j0, (i0 + 1) * kAzimuthSteps + j1};
  const float w[4] = {(1 - ti) * (1 - tj), (1 - ti) * tj, ti * (1 - tj), ti * tj};
  const Impl& m = *impl_;
  const int n = m.n;
  float* out[2] = {left, right};
  float delay[2] = {0, 0};
  for (int ear = 0; ear < 2; ++ear) {
    const float* __restrict a = m.ir(node[0], ear);
    const float* __restrict b = m.ir(node[1], ear);
    const float* __restrict c = m.ir(node[2], ear);
    const float* __restrict d = m.ir(node[3], ear);
    float* __restrict o = out[ear];  // the caller's buffers never alias the table
    const float w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3];
#pragma GCC ivdep
    for (int k = 0; k < n; ++k) o[k] = w0 * a[k] + w1 * b[k] + w2 * c[k] + w3 * d[k];
    for (int q = 0; q < 4; ++q) delay[ear] += w[q] * m.delays[size_t(node[q]) * 2 + size_t(ear)];
  }
  *leftDelaySamples = delay[0];
  *rightDelaySamples = delay[1];
}

HrirView Hrtf::nearestHrir(const float direction[3]) const {
  float az, el;
  toSpherical(direction, &az, &el);
  const int i =
      std::clamp(int(std::lround((el + 90.0f) / kGridStepDegrees)), 0, kElevationSteps - 1);
  const int j = int(std::lround(az / kGridStepDegrees)) % kAzimuthSteps;
  const int node = i * kAzimuthSteps + j;
  const Impl& m = *impl_;
  return {m.ir(node, 0), m.ir(node, 1), m.delays[size_t(node) * 2], m.delays[size_t(node) * 2 + 1]};
}

size_t Hrtf::measurementCount() const {
  return impl_->measured.size();
}

void Hrtf::measurement(size_t index, float direction[3], float* left, float* right,
                       float* leftDelaySamples, float* rightDelaySamples) const {
  const Impl& m = *impl_;
  const MeasuredDirection& d = m.measured.at(index);
  const MYSOFA_HRTF& h = *m.easy->hrtf;
  direction[0] = d.x;
  direction[1] = d.y;
  direction[2] = d.z;
  const float* src = h.DataIR.values + size_t(d.m) * h.R * h.N;  // [left | right]
  for (int k = 0; k < m.n; ++k) {
    left[k] = m.gain * src[k];
    right[k] = m.gain * src[size_t(h.N) + size_t(k)];
  }
  *leftDelaySamples = delayOf(h, d.m, 0);
  *rightDelaySamples = delayOf(h, d.m, 1);
}

void Hrtf::hrirExact(const float direction[3], float* left, float* right, float* leftDelaySamples,
                     float* rightDelaySamples) const {
  std::lock_guard<std::mutex> lock(impl_->easyMutex);
  impl_->exact(direction, left, right, leftDelaySamples, rightDelaySamples);
}

}  // namespace dpc::audio
