// Tests for audio/hrtf against the physics of a head: the MIT KEMAR set (Debian's
// /usr/share/libmysofa/default.sofa) must show the interaural level and time differences a
// real head gives, swap ears under left/right mirroring, resample with the rate, and reject
// bad files by name.
#include "audio/hrtf.h"

#include <array>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "common/input_error.h"

using dpc::audio::Hrtf;

namespace {

const std::string kKemar = Hrtf::kDefaultSofaPath;

struct Pair {
  std::vector<float> left, right;
  float leftDelay = 0, rightDelay = 0;
};

Pair lookup(const Hrtf& h, float x, float y, float z, bool exact = false) {
  Pair p;
  p.left.resize(size_t(h.filterLength()));
  p.right.resize(size_t(h.filterLength()));
  const float d[3] = {x, y, z};
  if (exact)
    h.hrirExact(d, p.left.data(), p.right.data(), &p.leftDelay, &p.rightDelay);
  else
    h.hrir(d, p.left.data(), p.right.data(), &p.leftDelay, &p.rightDelay);
  return p;
}

double energy(const std::vector<float>& x) {
  double e = 0;
  for (float v : x) e += double(v) * v;
  return e;
}

// Energy of x in [f1, f2] Hz: |X(f)|^2 summed over a DFT grid of spacing fs / 8192 (x
// zero-padded), evaluated directly. Only ratios between ears are used.
double bandEnergy(const std::vector<float>& x, int fs, double f1, double f2) {
  const int m = 8192;
  double e = 0;
  for (int k = int(std::ceil(f1 * m / fs)); k <= int(std::floor(f2 * m / fs)); ++k) {
    std::complex<double> s = 0;
    const double w = -2 * std::numbers::pi * k / m;
    for (size_t n = 0; n < x.size(); ++n) s += double(x[n]) * std::polar(1.0, w * double(n));
    e += std::norm(s);
  }
  return e;
}

// Lag (samples, sub-sample by parabolic interpolation of the peak) maximising
// sum_n l[n] r[n + lag], searched over |lag| <= maxLag: positive when the right ear lags.
double crossCorrelationLag(const std::vector<float>& l, const std::vector<float>& r, int maxLag) {
  const int n = int(l.size());
  auto xc = [&](int lag) {
    double s = 0;
    for (int i = 0; i < n; ++i)
      if (i + lag >= 0 && i + lag < n) s += double(l[size_t(i)]) * r[size_t(i + lag)];
    return s;
  };
  int best = -maxLag;
  double bestValue = xc(best);
  for (int lag = -maxLag + 1; lag <= maxLag; ++lag) {
    const double v = xc(lag);
    if (v > bestValue) best = lag, bestValue = v;
  }
  const double a = xc(best - 1), b = bestValue, c = xc(best + 1);
  const double denom = a - 2 * b + c;
  return best + (denom < 0 ? 0.5 * (a - c) / denom : 0.0);
}

// Relative RMS difference ||a - b|| / ||b||.
double relativeError(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0, r = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    d += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    r += double(b[i]) * b[i];
  }
  return std::sqrt(d / r);
}

std::array<float, 3> randomDirection(std::mt19937& rng) {
  std::normal_distribution<float> g;
  for (;;) {
    const float x = g(rng), y = g(rng), z = g(rng);
    const float r = std::sqrt(x * x + y * y + z * z);
    if (r > 1e-3f) return {x / r, y / r, z / r};
  }
}

}  // namespace

TEST_CASE("the KEMAR SOFA file loads at 44100 and 48000 Hz, filter length scales with rate") {
  const Hrtf h44 = Hrtf::load(kKemar, 44100);
  const Hrtf h48 = Hrtf::load(kKemar, 48000);
  CHECK(h44.sampleRate() == 44100);
  CHECK(h48.sampleRate() == 48000);
  // The file holds 512 taps at 44.1 kHz; libmysofa resamples to ceil(512 * 48000 / 44100).
  CHECK(h44.filterLength() == 512);
  CHECK(h48.filterLength() == int(std::ceil(512.0 * 48000.0 / 44100.0)));  // 558
  // Resampling keeps the time axis: the frontal HRIR's main peak sits at the same time.
  const Pair f44 = lookup(h44, 1, 0, 0), f48 = lookup(h48, 1, 0, 0);
  auto peakSeconds = [](const std::vector<float>& x, int fs) {
    size_t p = 0;
    for (size_t i = 0; i < x.size(); ++i)
      if (std::fabs(x[i]) > std::fabs(x[p])) p = i;
    return double(p) / fs;
  };
  CHECK(std::fabs(peakSeconds(f44.left, 44100) - peakSeconds(f48.left, 48000)) < 2.5e-5);
  // Our normalisation: per-ear energy 1 straight ahead, at both rates.
  CHECK((energy(f44.left) + energy(f44.right)) / 2 == Approx(1.0).epsilon(1e-4));
  CHECK((energy(f48.left) + energy(f48.right)) / 2 == Approx(1.0).epsilon(1e-4));
}

TEST_CASE("a source at the left: ILD > 6 dB in the 4 kHz octave, ITD 0.5..0.8 ms") {
  for (int fs : {44100, 48000}) {
    const Hrtf h = Hrtf::load(kKemar, fs);
    const Pair p = lookup(h, 0, 1, 0);  // azimuth 90 degrees: the left ear faces the source
    const double broadbandDb = 10 * std::log10(energy(p.left) / energy(p.right));
    // 4 kHz octave band, edges 4000 / sqrt(2) .. 4000 * sqrt(2) Hz.
    const double ildDb =
        10 * std::log10(bandEnergy(p.left, fs, 2828, 5657) / bandEnergy(p.right, fs, 2828, 5657));
    // ITD = (Data.Delay difference) + cross-correlation peak lag of the full-band HRIRs. KEMAR's
    // delays are zero (the ITD lives in the HRIRs), so the lag carries it all.
    const double lag = crossCorrelationLag(p.left, p.right, int(0.0015 * fs));
    const double itdMs = 1000.0 * ((p.rightDelay - p.leftDelay) + lag) / fs;
    // Woodworth, ITD = (a / c)(theta + sin theta): a = 8.75 cm, c = 343 m/s, theta = pi/2.
    const double woodworthMs = 1000.0 * 0.0875 / 343.0 * (std::numbers::pi / 2 + 1);
    std::printf(
        "KEMAR at %d Hz, source at 90 deg left: broadband ILD %.1f dB, 4 kHz octave ILD %.1f dB, "
        "ITD %.3f ms (delays %.2f/%.2f samples + xcorr lag %.2f samples; Woodworth %.3f ms)\n",
        fs, broadbandDb, ildDb, itdMs, p.leftDelay, p.rightDelay, lag, woodworthMs);
    CHECK(energy(p.left) > energy(p.right));
    CHECK(ildDb > 6.0);
    CHECK(itdMs > 0.5);
    CHECK(itdMs < 0.8);
    // And the source on the right gives the mirror image: negative ITD.
    const Pair q = lookup(h, 0, -1, 0);
    CHECK(crossCorrelationLag(q.left, q.right, int(0.0015 * fs)) == Approx(-lag).margin(0.05));
  }
}

TEST_CASE("mirrored directions swap ears") {
  // The MIT KEMAR SOFA set is exactly left/right symmetric (its right ear is the mirrored left
  // ear), and both the grid and its fill are symmetric about the median plane, so
  // left(x, y, z) = right(x, -y, z) up to float rounding: tolerance 1e-4 relative RMS.
  // libmysofa's own interpolation is not symmetric; its figure is printed for comparison.
  const Hrtf h = Hrtf::load(kKemar, 48000);
  std::mt19937 rng(7);
  double worst = 0, worstExact = 0;
  for (int t = 0; t < 200; ++t) {
    const auto d = randomDirection(rng);
    const Pair a = lookup(h, d[0], d[1], d[2]), b = lookup(h, d[0], -d[1], d[2]);
    worst = std::max({worst, relativeError(a.left, b.right), relativeError(a.right, b.left)});
    CHECK(a.leftDelay == Approx(b.rightDelay).margin(1e-4));
    const Pair ae = lookup(h, d[0], d[1], d[2], true), be = lookup(h, d[0], -d[1], d[2], true);
    worstExact =
        std::max({worstExact, relativeError(ae.left, be.right), relativeError(ae.right, be.left)});
  }
  std::printf(
      "mirror symmetry, worst relative RMS difference over 200 directions: grid %.2e, libmysofa "
      "mysofa_getfilter_float %.2e\n",
      worst, worstExact);
  CHECK(worst < 1e-4);
}

TEST_CASE("the grid equals the measurements on them and is continuous between them") {
  const Hrtf h = Hrtf::load(kKemar, 48000);
  // KEMAR rings at elevations -20..20 degrees are measured every 5 degrees of azimuth, so these
  // grid nodes are measurements: the grid must return them (libmysofa returns a measurement
  // unchanged when the direction hits it).
  for (float azDeg : {0.0f, 35.0f, 90.0f, 215.0f, 300.0f}) {
    for (float elDeg : {-20.0f, 0.0f, 10.0f}) {
      const float az = azDeg * float(std::numbers::pi / 180);
      const float el = elDeg * float(std::numbers::pi / 180);
      const float x = std::cos(el) * std::cos(az), y = std::cos(el) * std::sin(az),
                  z = std::sin(el);
      const Pair g = lookup(h, x, y, z), e = lookup(h, x, y, z, true);
      CHECK(relativeError(g.left, e.left) < 1e-4);
      CHECK(relativeError(g.right, e.right) < 1e-4);
      const float d[3] = {x, y, z};
      const auto v = h.nearestHrir(d);
      CHECK(relativeError(std::vector<float>(v.left, v.left + h.filterLength()), e.left) < 1e-4);
    }
  }
  // Continuity: sweep the azimuth in 0.25 degree steps along elevation 5 degrees (between two
  // measured rings) and record the largest change of per-ear level (dB) and waveform (relative
  // RMS) from one step to the next.
  double jumpDb = 0, jumpRel = 0, jumpDbExact = 0, jumpRelExact = 0;
  Pair prev = lookup(h, 1, 0, 0), prevExact = prev;
  const float el = 5.0f * float(std::numbers::pi / 180);
  for (int s = 0; s <= 360 * 4; ++s) {
    const float az = 0.25f * float(s) * float(std::numbers::pi / 180);
    const float x = std::cos(el) * std::cos(az), y = std::cos(el) * std::sin(az), z = std::sin(el);
    const Pair g = lookup(h, x, y, z), e = lookup(h, x, y, z, true);
    if (s > 0) {
      for (int ear = 0; ear < 2; ++ear) {
        const auto& a = ear ? g.right : g.left;
        const auto& b = ear ? prev.right : prev.left;
        const auto& ae = ear ? e.right : e.left;
        const auto& be = ear ? prevExact.right : prevExact.left;
        jumpDb = std::max(jumpDb, std::fabs(10 * std::log10(energy(a) / energy(b))));
        jumpRel = std::max(jumpRel, relativeError(a, b));
        jumpDbExact = std::max(jumpDbExact, std::fabs(10 * std::log10(energy(ae) / energy(be))));
        jumpRelExact = std::max(jumpRelExact, relativeError(ae, be));
      }
    }
    prev = g;
    prevExact = e;
  }
  std::printf(
      "azimuth sweep at 5 deg elevation, 0.25 deg steps, largest step-to-step change: grid %.2f "
      "dB / %.3f relative RMS; libmysofa %.2f dB / %.3f\n",
      jumpDb, jumpRel, jumpDbExact, jumpRelExact);
  CHECK(jumpDb < 0.5);
  CHECK(jumpRel < 0.1);
  // Off the measurements the two interpolations differ; print how much.
  std::mt19937 rng(11);
  double worstLevelDb = 0, meanRel = 0, meanRelNearest = 0;
  int count = 0;
  for (int t = 0; t < 300; ++t) {
    const auto d = randomDirection(rng);
    if (d[2] < std::sin(-40.0f * float(std::numbers::pi / 180))) continue;  // measured region
    const Pair g = lookup(h, d[0], d[1], d[2]), e = lookup(h, d[0], d[1], d[2], true);
    const auto v = h.nearestHrir(d.data());
    for (int ear = 0; ear < 2; ++ear) {
      const auto& gi = ear ? g.right : g.left;
      const auto& ei = ear ? e.right : e.left;
      worstLevelDb = std::max(worstLevelDb, std::fabs(10 * std::log10(energy(gi) / energy(ei))));
      meanRel += relativeError(gi, ei);
      const float* vi = ear ? v.right : v.left;
      meanRelNearest += relativeError(std::vector<float>(vi, vi + h.filterLength()), ei);
    }
    count += 2;
  }
  std::printf(
      "grid vs libmysofa over %d ear filters (elevation >= -40 deg): worst level difference "
      "%.2f dB, mean relative RMS difference %.3f (bilinear) / %.3f (nearest node)\n",
      count, worstLevelDb, meanRel / count, meanRelNearest / count);
  CHECK(worstLevelDb < 3.0);
}

TEST_CASE("measurement() returns the SOFA measurements with the grid normalisation") {
  // KEMAR: 710 directions at one radius. Every measurement is a unit direction; where the
  // grid has a node on a measurement (elevations -20..20 every 5 degrees of azimuth) the
  // node is that measurement, so measurement() and hrir() agree to float rounding.
  const Hrtf h = Hrtf::load(kKemar, 48000);
  REQUIRE(h.measurementCount() == 710);
  Pair m;
  m.left.resize(size_t(h.filterLength()));
  m.right.resize(size_t(h.filterLength()));
  int onGrid = 0;
  for (size_t q = 0; q < h.measurementCount(); ++q) {
    float u[3];
    h.measurement(q, u, m.left.data(), m.right.data(), &m.leftDelay, &m.rightDelay);
    CHECK(std::hypot(u[0], u[1], u[2]) == Approx(1.0).margin(1e-6));
    CHECK(m.leftDelay == 0.f);  // KEMAR's delays are inside its HRIRs
    const double az = std::atan2(u[1], u[0]) * 180 / std::numbers::pi,
                 el = std::asin(u[2]) * 180 / std::numbers::pi;
    const bool node = std::abs(el) <= 20.5 && std::abs(el - 5 * std::round(el / 5)) < 1e-3 &&
                      std::abs(az - 5 * std::round(az / 5)) < 1e-3;
    if (!node) continue;
    ++onGrid;
    const Pair g = lookup(h, u[0], u[1], u[2]);
    CHECK(relativeError(g.left, m.left) < 1e-4);
    CHECK(relativeError(g.right, m.right) < 1e-4);
  }
  CHECK(onGrid == 5 * 72);
  CHECK_THROWS_AS(h.measurement(710, nullptr, nullptr, nullptr, nullptr, nullptr),
                  std::out_of_range);
}

TEST_CASE("a zero or non-finite direction is treated as straight ahead") {
  const Hrtf h = Hrtf::load(kKemar, 48000);
  const Pair front = lookup(h, 1, 0, 0);
  const Pair zero = lookup(h, 0, 0, 0);
  const Pair nan = lookup(h, std::nanf(""), 0, 0);
  CHECK(relativeError(zero.left, front.left) < 1e-6);
  CHECK(relativeError(nan.right, front.right) < 1e-6);
}

TEST_CASE("concurrent lookups from several threads give identical filters") {
  const Hrtf h = Hrtf::load(kKemar, 48000);
  std::mt19937 rng(3);
  std::vector<std::array<float, 3>> dirs(64);
  for (auto& d : dirs) d = randomDirection(rng);
  std::vector<Pair> expected;
  for (const auto& d : dirs) expected.push_back(lookup(h, d[0], d[1], d[2]));
  std::vector<int> mismatches(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int rep = 0; rep < 20; ++rep)
        for (size_t i = 0; i < dirs.size(); ++i) {
          const bool exact = (rep % 5 == 0);  // hrirExact is serialised internally
          const Pair p = lookup(h, dirs[i][0], dirs[i][1], dirs[i][2], exact);
          if (!exact && (p.left != expected[i].left || p.right != expected[i].right))
            ++mismatches[size_t(t)];
        }
    });
  for (auto& th : threads) th.join();
  for (int m : mismatches) CHECK(m == 0);
}

TEST_CASE("missing and invalid SOFA files throw InputError naming the file") {
  const std::string missing = std::string(DPC_BINARY_DIR) + "/no_such_hrtf.sofa";
  try {
    (void)Hrtf::load(missing, 48000);
    FAIL("no exception");
  } catch (const dpc::InputError& e) {
    CHECK(e.file() == missing);
    CHECK(std::string(e.what()).find(missing) == 0);
    CHECK(std::string(e.what()).find("No such file") != std::string::npos);
  }
  const std::string text = std::string(DPC_BINARY_DIR) + "/hrtf_test_not_a_sofa.sofa";
  std::ofstream(text) << "this is a text file, not HDF5\n";
  try {
    (void)Hrtf::load(text, 48000);
    FAIL("no exception");
  } catch (const dpc::InputError& e) {
    CHECK(e.file() == text);
    CHECK(std::string(e.what()).find("not a valid SOFA file") != std::string::npos);
  }
  std::remove(text.c_str());
  CHECK_THROWS_AS(Hrtf::load(kKemar, 1000), std::invalid_argument);
}

TEST_CASE("load and lookup cost (printed, not asserted)") {
  const auto tLoad = std::chrono::steady_clock::now();
  const Hrtf h = Hrtf::load(kKemar, 48000);
  std::printf(
      "Hrtf::load(KEMAR, 48000): %.0f ms\n",
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tLoad).count());
  std::mt19937 rng(5);
  std::vector<std::array<float, 3>> dirs(1024);
  for (auto& d : dirs) d = randomDirection(rng);
  std::vector<float> l(size_t(h.filterLength())), r(l.size());
  float dl, dr, sink = 0;
  auto time = [&](auto&& f, int calls) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) f(dirs[size_t(i) % dirs.size()].data());
    const auto t1 = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / calls;
  };
  const double bilinear = time(
      [&](const float* d) {
        h.hrir(d, l.data(), r.data(), &dl, &dr);
        sink += l[7];
      },
      20000);
  const double nearest = time([&](const float* d) { sink += h.nearestHrir(d).left[7]; }, 200000);
  const double exact = time(
      [&](const float* d) {
        h.hrirExact(d, l.data(), r.data(), &dl, &dr);
        sink += l[7];
      },
      5000);
  std::printf(
      "HRIR lookup at 48 kHz (%d taps): bilinear grid %.0f ns, nearest node %.0f ns, libmysofa "
      "direct %.0f ns per call (sink %g)\n",
      h.filterLength(), bilinear, nearest, exact, double(sink));
  CHECK(std::isfinite(sink));
}
