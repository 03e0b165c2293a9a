#include "engine/gap_probe.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <memory>
#include <numbers>
#include <vector>

#include "engine/slit.h"

namespace dpc {

namespace {

constexpr int kSteps = 8;           // points per probe and round: 2 rays each, one 16-ray packet
constexpr float kLegStart = 1e-3f;  // m: the legs start this far from the source and listener
constexpr float kInnerWidth = 0.5f; // along the edge: a gap is free this many widths across
constexpr float kOuterWidth = 1.5f; // and closed within this many

// Along the edge the points lie 1 .. kSteps / 2 widths either side of Q: up to the aspect at
// which the slit model holds fully.
static_assert(kSteps == int(kSlitFullAspect));

using Points = std::array<glm::vec3, kSteps>;
using Valid = std::array<bool, kSteps>;

/// kSteps values from lo to hi evenly in log, both included (`inner`: strictly between).
std::array<float, kSteps> deltas(float lo, float hi, bool inner) {
  std::array<float, kSteps> d{};
  const double ratio = double(hi) / double(lo);
  for (int i = 0; i < kSteps; ++i) {
    const double t = inner ? double(i + 1) / (kSteps + 1) : double(i) / (kSteps - 1);
    d[size_t(i)] = float(double(lo) * std::pow(ratio, t));
  }
  return d;
}

/// The probe points Q + delta u for each delta.
Points across(const GapProbe& g, const std::array<float, kSteps>& d) {
  Points p;
  for (int i = 0; i < kSteps; ++i) p[size_t(i)] = g.q + d[size_t(i)] * g.mouth;
  return p;
}

/// True when p lies in the edge's own solid (outside the air wedge seen along the edge).
bool inSolid(const GapProbe& g, const glm::vec3& p) {
  const glm::vec3 v = p - g.q;
  double a = std::atan2(double(glm::dot(v, g.turn)), double(glm::dot(v, g.face0)));
  if (a < 0.0) a += 2.0 * std::numbers::pi;
  return a > double(g.airWedge);
}

/// The two legs to p, each running min(kGapProbeThrough, its distance from the edge line) past
/// p unless that would end in the edge's own solid (then they stop at p). An inactive pair
/// for a point not to be tested.
void appendLegs(const glm::vec3& source, const glm::vec3& listener, const GapProbe& g,
                const glm::vec3& p, bool valid, std::vector<TraceRay>& rays) {
  const glm::vec3 off = p - g.q;
  const float fromEdge = glm::length(off - glm::dot(off, g.along) * g.along);
  for (const glm::vec3& from : {source, listener}) {
    const glm::vec3 v = p - from;
    const float length = glm::length(v);
    if (!valid || !(length > kLegStart)) {
      rays.push_back(TraceRay{from, glm::vec3(1.f, 0.f, 0.f), 0.f, 0.f, false});
      continue;
    }
    const glm::vec3 dir = v / length;
    float through = std::min(kGapProbeThrough, fromEdge);
    if (inSolid(g, p + through * dir)) through = 0.f;
    rays.push_back(TraceRay{from, dir, kLegStart, length + through});
  }
}

/// Tests every point of the listed probes (both legs free?); blocked[n][i] for probe active[n].
std::vector<Valid> runRound(const Tracer& tracer, const glm::vec3& source,
                            const glm::vec3& listener, std::span<const GapProbe> probes,
                            const std::vector<size_t>& active, const std::vector<Points>& points,
                            const std::vector<Valid>& valid) {
  std::vector<TraceRay> rays;
  rays.reserve(active.size() * 2 * kSteps);
  for (size_t n = 0; n < active.size(); ++n)
    for (int i = 0; i < kSteps; ++i)
      appendLegs(source, listener, probes[active[n]], points[n][size_t(i)], valid[n][size_t(i)],
                 rays);
  const std::unique_ptr<bool[]> hit(new bool[rays.size()]());
  tracer.occluded(rays, std::span<bool>(hit.get(), rays.size()));
  std::vector<Valid> blocked(active.size());
  for (size_t n = 0; n < active.size(); ++n)
    for (size_t i = 0; i < kSteps; ++i)
      blocked[n][i] = hit[(n * kSteps + i) * 2] || hit[(n * kSteps + i) * 2 + 1];
  return blocked;
}

int firstBlocked(const Valid& blocked) {
  for (int i = 0; i < kSteps; ++i)
    if (blocked[size_t(i)]) return i;
  return kSteps;
}

/// Tests the points of the listed probes, every point valid.
std::vector<Valid> runAcross(const Tracer& tracer, const glm::vec3& source,
                             const glm::vec3& listener, std::span<const GapProbe> probes,
                             const std::vector<size_t>& active,
                             const std::vector<std::array<float, kSteps>>& d) {
  std::vector<Points> points;
  for (size_t n = 0; n < active.size(); ++n) points.push_back(across(probes[active[n]], d[n]));
  Valid all;
  all.fill(true);
  return runRound(tracer, source, listener, probes, active, points,
                  std::vector<Valid>(active.size(), all));
}

/// The width by deltas across the mouth: a log grid up to the reach, then one refined
/// between its last free and first blocked delta.
void findWidths(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
                std::span<const GapProbe> probes, std::span<GapShape> shapes) {
  std::vector<size_t> active;
  std::vector<std::array<float, kSteps>> d;
  for (size_t j = 0; j < probes.size(); ++j) {
    shapes[j] = GapShape{};
    if (!(probes[j].reach > kGapNarrowest)) continue;
    active.push_back(j);
    d.push_back(deltas(kGapNarrowest, probes[j].reach, false));
  }
  if (active.empty()) return;
  const auto coarse = runAcross(tracer, source, listener, probes, active, d);
  std::vector<size_t> refine;
  std::vector<std::array<float, 2>> bracket;
  std::vector<std::array<float, kSteps>> fine;
  for (size_t n = 0; n < active.size(); ++n) {
    // Blocked everywhere: closed. Blocked only next to the edge, free further out: a leg
    // grazing the edge's own face within rounding (seen 60 m from a wedge's apex), no gap.
    int free = 0;
    while (free < kSteps && coarse[n][size_t(free)]) ++free;
    if (free == kSteps) {
      shapes[active[n]].width = -1.f;
      continue;
    }
    int f = free;
    while (f < kSteps && !coarse[n][size_t(f)]) ++f;
    if (f == kSteps) continue;  // free within reach: width 0
    refine.push_back(active[n]);
    bracket.push_back({d[n][size_t(f - 1)], d[n][size_t(f)]});
    fine.push_back(deltas(bracket.back()[0], bracket.back()[1], true));
  }
  if (refine.empty()) return;
  const auto blocked = runAcross(tracer, source, listener, probes, refine, fine);
  for (size_t n = 0; n < refine.size(); ++n) {
    const int f = firstBlocked(blocked[n]);
    const float lo = f == 0 ? bracket[n][0] : fine[n][size_t(f - 1)];
    const float hi = f == kSteps ? bracket[n][1] : fine[n][size_t(f)];
    shapes[refine[n]].width = std::sqrt(lo * hi);
  }
}

}  // namespace

void probeGaps(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
               std::span<const GapProbe> probes, std::span<GapShape> shapes) {
  findWidths(tracer, source, listener, probes, shapes);
  // Along the edge, 1 .. 4 widths either side of Q: is there still a gap (free at half a width
  // across the mouth) that closes within 1.5 widths?
  std::vector<size_t> active;
  std::vector<Points> inner, outer;
  std::vector<Valid> valid;
  for (size_t j = 0; j < probes.size(); ++j) {
    const float w = shapes[j].width;
    if (!(w > 0.f)) continue;
    Points in, out;
    Valid v;
    for (int i = 0; i < kSteps; ++i) {
      const float a = float(i < kSteps / 2 ? -(i + 1) : i - kSteps / 2 + 1) * w;
      v[size_t(i)] = a >= probes[j].from && a <= probes[j].to;
      const glm::vec3 base = probes[j].q + a * probes[j].along;
      in[size_t(i)] = base + kInnerWidth * w * probes[j].mouth;
      out[size_t(i)] = base + kOuterWidth * w * probes[j].mouth;
    }
    active.push_back(j);
    inner.push_back(in);
    outer.push_back(out);
    valid.push_back(v);
  }
  if (active.empty()) return;
  const auto open = runRound(tracer, source, listener, probes, active, inner, valid);
  const auto shut = runRound(tracer, source, listener, probes, active, outer, valid);
  for (size_t n = 0; n < active.size(); ++n) {
    int run = 0;
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < kSteps / 2; ++i) {
        const size_t k = size_t(side * kSteps / 2 + i);
        if (!valid[n][k] || open[n][k] || !shut[n][k]) break;
        ++run;
      }
    shapes[active[n]].aspect = float(run);
  }
}

}  // namespace dpc
