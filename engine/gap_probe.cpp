#include "engine/gap_probe.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <memory>
#include <numbers>
#include <vector>

namespace dpc {

namespace {

constexpr int kSteps = 8;           // deltas per round: 2 rays each, one 16-ray packet
constexpr float kLegStart = 1e-3f;  // m: the legs start this far from the source and listener

/// The deltas of one round: kSteps values from lo to hi evenly in log, both included
/// (`inner`: strictly between them instead).
std::array<float, kSteps> deltas(float lo, float hi, bool inner) {
  std::array<float, kSteps> d{};
  const double ratio = double(hi) / double(lo);
  for (int i = 0; i < kSteps; ++i) {
    const double t = inner ? double(i + 1) / (kSteps + 1) : double(i) / (kSteps - 1);
    d[size_t(i)] = float(double(lo) * std::pow(ratio, t));
  }
  return d;
}

/// True when p lies in the edge's own solid (outside the air wedge seen along the edge).
bool inSolid(const GapProbe& g, const glm::vec3& p) {
  const glm::vec3 v = p - g.q;
  double a = std::atan2(double(glm::dot(v, g.turn)), double(glm::dot(v, g.face0)));
  if (a < 0.0) a += 2.0 * std::numbers::pi;
  return a > double(g.airWedge);
}

/// The two legs to P = q + delta u, each running min(kGapProbeThrough, delta) past P unless
/// that would end in the edge's own solid (then they stop at P).
void appendLegs(const glm::vec3& source, const glm::vec3& listener, const GapProbe& g,
                float delta, std::vector<TraceRay>& rays) {
  const glm::vec3 p = g.q + delta * g.mouth;
  for (const glm::vec3& from : {source, listener}) {
    const glm::vec3 v = p - from;
    const float length = glm::length(v);
    if (!(length > kLegStart)) {
      rays.push_back(TraceRay{from, glm::vec3(1.f, 0.f, 0.f), 0.f, 0.f, false});
      continue;
    }
    const glm::vec3 dir = v / length;
    float through = std::min(kGapProbeThrough, delta);
    if (inSolid(g, p + through * dir)) through = 0.f;
    rays.push_back(TraceRay{from, dir, kLegStart, length + through});
  }
}

/// One round for every probe still open: the rays, then per probe the index of the first
/// blocked delta (kSteps when none).
void runRound(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
              std::span<const GapProbe> probes, const std::vector<std::array<float, kSteps>>& d,
              const std::vector<size_t>& active, std::vector<int>& firstBlocked) {
  std::vector<TraceRay> rays;
  rays.reserve(active.size() * 2 * kSteps);
  for (size_t j : active)
    for (float delta : d[j]) appendLegs(source, listener, probes[j], delta, rays);
  const std::unique_ptr<bool[]> blocked(new bool[rays.size()]());
  tracer.occluded(rays, std::span<bool>(blocked.get(), rays.size()));
  for (size_t n = 0; n < active.size(); ++n) {
    int first = kSteps;
    for (int i = 0; i < kSteps && first == kSteps; ++i)
      if (blocked[n * 2 * kSteps + 2 * size_t(i)] || blocked[n * 2 * kSteps + 2 * size_t(i) + 1])
        first = i;
    firstBlocked[active[n]] = first;
  }
}

}  // namespace

void probeGapWidths(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
                    std::span<const GapProbe> probes, std::span<float> widths) {
  std::vector<std::array<float, kSteps>> d(probes.size());
  std::vector<size_t> active;
  std::vector<int> first(probes.size(), kSteps);
  for (size_t j = 0; j < probes.size(); ++j) {
    widths[j] = 0.f;
    if (!(probes[j].reach > kGapNarrowest)) continue;
    d[j] = deltas(kGapNarrowest, probes[j].reach, false);
    active.push_back(j);
  }
  if (active.empty()) return;
  runRound(tracer, source, listener, probes, d, active, first);
  // Refine between the last free and the first blocked delta.
  std::vector<size_t> refine;
  std::vector<std::array<float, 2>> bracket(probes.size());
  for (size_t j : active) {
    if (first[j] == kSteps) continue;  // free within reach
    if (first[j] == 0) {
      widths[j] = -1.f;  // closed
      continue;
    }
    bracket[j] = {d[j][size_t(first[j] - 1)], d[j][size_t(first[j])]};
    d[j] = deltas(bracket[j][0], bracket[j][1], true);
    refine.push_back(j);
  }
  if (refine.empty()) return;
  runRound(tracer, source, listener, probes, d, refine, first);
  for (size_t j : refine) {
    const float lo = first[j] == 0 ? bracket[j][0] : d[j][size_t(first[j] - 1)];
    const float hi = first[j] == kSteps ? bracket[j][1] : d[j][size_t(first[j])];
    widths[j] = std::sqrt(lo * hi);
  }
}

}  // namespace dpc
