#include "engine/gap_probe.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>
#include <vector>

#include "engine/slit.h"

namespace dpc {

namespace {

constexpr int kCoarse = 4;           // deltas of the first round (every path: 8 rays)
constexpr int kFine = 8;             // deltas of each refining round (gaps only)
constexpr int kAlong = 4;            // points along the edge either side of Q
constexpr float kLegStart = 1e-3f;   // m: the legs start this far from the source and listener
constexpr float kInnerWidth = 0.5f;  // along the edge: a gap is free this many widths across
constexpr float kOuterWidth = 1.5f;  // and closed within this many
/// Or closed this many widths across: a far side met at a slant (a leaf ajar, its face running
/// past the jamb's corner) closes the gap just past its width and may be clear by kOuterWidth,
/// where the point has left the gap beside the leaf's rim.
constexpr float kMiddleWidth = 1.2f;
/// Points per test of a gap along its edge (addGapTest): inner, open, middle, outer.
constexpr size_t kGapTestPoints = 4;
constexpr float kFlank = 0.04f;      // m: where a free Q's flanks are probed (probeFlanks)
constexpr int kEndSteps = 8;         // bisection steps for where a gap ends (findEnds)

// Along the edge the points lie 1 .. kAlong widths either side of Q: up to the aspect at which
// the slit model holds fully.
static_assert(2 * kAlong == int(kSlitFullAspect));

/// n values from lo to hi evenly in log, both included (`inner`: strictly between them).
std::vector<float> deltas(float lo, float hi, int n, bool inner) {
  std::vector<float> d(static_cast<size_t>(n));
  const double ratio = double(hi) / double(lo);
  for (int i = 0; i < n; ++i) {
    const double t = inner ? double(i + 1) / (n + 1) : double(i) / (n - 1);
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

/// The points of one round: which probe each belongs to, and whether it is to be tested.
struct Round {
  std::vector<size_t> probe;
  std::vector<glm::vec3> point;
  std::vector<bool> valid;
  void add(size_t j, const glm::vec3& p, bool v = true) {
    probe.push_back(j);
    point.push_back(p);
    valid.push_back(v);
  }
};

/// P's distance from the edge's line, m: how far across the mouth it lies.
float distanceFromEdge(const GapProbe& g, const glm::vec3& p) {
  const glm::vec3 off = p - g.q;
  return glm::length(off - glm::dot(off, g.along) * g.along);
}

/// The two legs to p, each running min(kGapProbeThrough, p's distance from the edge line) past
/// p unless that would end in the edge's own solid (then they stop at p). An inactive pair
/// for a point not to be tested.
void appendLegs(const glm::vec3& source, const glm::vec3& listener, const GapProbe& g,
                const glm::vec3& p, bool valid, std::vector<TraceRay>& rays) {
  const float fromEdge = distanceFromEdge(g, p);
  const bool channel = g.through != glm::vec3(0.f);
  for (int leg = 0; leg < 2; ++leg) {
    const glm::vec3& from = leg == 0 ? source : listener;
    const glm::vec3 to = leg == 0 ? p : p + g.through;
    const glm::vec3 v = to - from;
    const float length = glm::length(v);
    if (!valid || !(length > kLegStart) || (leg == 0 ? g.turnedIn : g.turnedOut)) {
      rays.push_back(TraceRay{from, glm::vec3(1.f, 0.f, 0.f), 0.f, 0.f, false});
      continue;
    }
    const glm::vec3 dir = v / length;
    float through = std::min(kGapProbeThrough, fromEdge);
    if (inSolid(g, p + through * dir) || (channel && leg == 1)) through = 0.f;
    rays.push_back(TraceRay{from, dir, kLegStart, length + through});
  }
}

/// True when a leg's hit closes the mouth at P: the surface hit lies within P's distance from
/// the edge of P (the other side of a gap that wide, at any angle to the mouth), or, taken as
/// its plane there, crosses the mouth between the edge and P (the foot of P on the edge's line
/// and P on its two sides or on it, within the legs' run past P: a sheet flush with the edge's
/// own, a floor under a partition's rim that a low leg reaches far from P). A surface farther
/// away that leaves the mouth open up to P (the free edge of a leaf ajar, a lintel half a metre
/// behind the mouth) only hides P from the source or the listener: that is another edge's
/// shadow, not the other side of a gap, and the point counts as free.
bool closesMouth(const GapProbe& g, const TraceRay& leg, const TraceHit& hit, const glm::vec3& p) {
  if (!hit.found) return false;
  const glm::vec3 at = leg.org + hit.surface.t * leg.dir;
  const glm::vec3 foot = g.q + glm::dot(p - g.q, g.along) * g.along;
  if (glm::length(p - at) <= glm::length(p - foot) + kGapProbeThrough) return true;
  const float dp = glm::dot(p - at, hit.surface.normal);
  const float df = glm::dot(foot - at, hit.surface.normal);
  return !((dp > kGapProbeThrough && df > kGapProbeThrough) ||
           (dp < -kGapProbeThrough && df < -kGapProbeThrough));
}

/// The segment across the mouth from the edge's line to p (inactive at the line): a surface it
/// meets closes the gap within p's distance (the reveal beside a leaf set in a thick wall,
/// whose legs meet the wall's faces first, which closesMouth takes for another edge's shadow).
TraceRay acrossRay(const GapProbe& g, const glm::vec3& p, bool valid) {
  const glm::vec3 foot = g.q + glm::dot(p - g.q, g.along) * g.along;
  const float length = glm::distance(foot, p);
  if (!valid || !(length > 0.f)) return TraceRay{p, glm::vec3(1.f, 0.f, 0.f), 0.f, 0.f, false};
  return TraceRay{foot, (p - foot) / length, surfaceOffset(foot), length};
}

/// A channel's segment from p at its front mouth to p + through at its back one (inactive for
/// other probes): a surface on it closes the channel that far across (a moving leaf set in a
/// thick wall's doorway, beside the reveal the channel runs along).
TraceRay throughRay(const GapProbe& g, const glm::vec3& p, bool valid) {
  const float length = glm::length(g.through);
  if (!valid || !(length > 0.f)) return TraceRay{p, glm::vec3(1.f, 0.f, 0.f), 0.f, 0.f, false};
  return TraceRay{p, g.through / length, surfaceOffset(p), length};
}

/// Per point of the round, the triangle whose surface closes the mouth there (closesMouth, or
/// met across the mouth or through a channel), the source's leg's first; kNoCloser where none
/// does (and for untested points).
std::vector<uint32_t> run(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
                      std::span<const GapProbe> probes, const Round& round) {
  constexpr size_t kRays = 4;  // two legs, across the mouth, through a channel
  std::vector<TraceRay> rays;
  rays.reserve(round.point.size() * kRays);
  for (size_t i = 0; i < round.point.size(); ++i) {
    const GapProbe& g = probes[round.probe[i]];
    appendLegs(source, listener, g, round.point[i], round.valid[i], rays);
    rays.push_back(acrossRay(g, round.point[i], round.valid[i]));
    rays.push_back(throughRay(g, round.point[i], round.valid[i]));
  }
  std::vector<TraceHit> hits(rays.size());
  tracer.intersect(rays, hits);
  std::vector<uint32_t> closer(round.point.size(), kNoCloser);
  for (size_t i = 0; i < closer.size(); ++i) {
    const GapProbe& g = probes[round.probe[i]];
    const glm::vec3& p = round.point[i];
    for (const size_t ray : {kRays * i + 3, kRays * i + 2})
      if (hits[ray].found) closer[i] = hits[ray].surface.triangle;
    GapProbe back = g;  // the listener's leg goes to the back mouth
    back.q += g.through;
    for (const size_t leg : {kRays * i + 1, kRays * i}) {
      const bool listener = leg == kRays * i + 1;
      if (closesMouth(listener ? back : g, rays[leg], hits[leg], listener ? p + g.through : p))
        closer[i] = hits[leg].surface.triangle;
    }
  }
  return closer;
}

/// The deltas of one probe in a round across the mouth, and the points for them.
struct Across {
  size_t probe;
  std::vector<float> d;
};

std::vector<uint32_t> runAcross(const Tracer& tracer, const glm::vec3& source,
                            const glm::vec3& listener, std::span<const GapProbe> probes,
                            const std::vector<Across>& list) {
  Round round;
  for (const Across& a : list)
    for (float delta : a.d) round.add(a.probe, probes[a.probe].q + delta * probes[a.probe].mouth);
  return run(tracer, source, listener, probes, round);
}

/// A gap's width bracketed: the last free delta, the first closed one (m) and what closes it
/// there (run).
struct Bracket {
  float free, closed;
  uint32_t closer;
};

/// Refines each listed bracket by kFine deltas strictly inside it; returns the new brackets.
std::vector<Bracket> refine(const Tracer& tracer, const glm::vec3& source,
                            const glm::vec3& listener, std::span<const GapProbe> probes,
                            const std::vector<size_t>& gaps, const std::vector<Bracket>& bracket) {
  std::vector<Across> list;
  for (size_t n = 0; n < gaps.size(); ++n)
    list.push_back({gaps[n], deltas(bracket[n].free, bracket[n].closed, kFine, true)});
  const std::vector<uint32_t> closer = runAcross(tracer, source, listener, probes, list);
  std::vector<Bracket> out = bracket;
  for (size_t n = 0; n < list.size(); ++n) {
    const auto& d = list[n].d;
    for (int i = 0; i < kFine; ++i) {
      const uint32_t c = closer[n * kFine + size_t(i)];
      if (c != kNoCloser) {
        out[n].closed = d[size_t(i)];
        out[n].closer = c;
        break;
      }
      out[n].free = d[size_t(i)];
    }
  }
  return out;
}

/// For each gap's bracket, the coarse deltas' geometric means below it (between the first free
/// delta and the bracket's free one): the first of them that is closed brackets the gap
/// instead. A gap may close and open again across its mouth: a sheet's rim a few millimetres
/// in front of a 0.2 m wall, probed in the sheet's plane, passes the wall's corner closed from
/// 7 to 43 mm and beyond meets the wall's back face, far enough not to close it.
std::vector<Bracket> closedBelow(const Tracer& tracer, const glm::vec3& source,
                                 const glm::vec3& listener, std::span<const GapProbe> probes,
                                 const std::vector<size_t>& gaps,
                                 const std::vector<std::vector<float>>& below,
                                 std::vector<Bracket> bracket) {
  std::vector<Across> list;
  std::vector<size_t> first;  // per gap, its first point in the round
  for (size_t n = 0; n < gaps.size(); ++n) {
    first.push_back(list.empty() ? 0 : first.back() + list.back().d.size());
    std::vector<float> mid;
    for (size_t i = 0; i + 1 < below[n].size(); ++i)
      mid.push_back(std::sqrt(below[n][i] * below[n][i + 1]));
    list.push_back({gaps[n], mid});
  }
  const std::vector<uint32_t> closer = runAcross(tracer, source, listener, probes, list);
  for (size_t n = 0; n < gaps.size(); ++n)
    for (size_t i = 0; i < list[n].d.size(); ++i)
      if (const uint32_t c = closer[first[n] + i]; c != kNoCloser) {
        bracket[n] = {below[n][i], list[n].d[i], c};
        break;
      }
  return bracket;
}

/// The width by deltas across the mouth: kCoarse deltas in log up to the reach, their means
/// below a gap's bracket (closedBelow), then two rounds refining the bracket between the last
/// free and the first blocked one.
void findWidths(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
                std::span<const GapProbe> probes, std::span<GapShape> shapes) {
  std::vector<Across> list;
  for (size_t j = 0; j < probes.size(); ++j) {
    shapes[j] = GapShape{};
    if (probes[j].reach > kGapNarrowest)
      list.push_back({j, deltas(kGapNarrowest, probes[j].reach, kCoarse, false)});
  }
  if (list.empty()) return;
  const std::vector<uint32_t> coarse = runAcross(tracer, source, listener, probes, list);
  std::vector<size_t> gaps;
  std::vector<Bracket> bracket;
  std::vector<std::vector<float>> below;  // per gap, its free coarse deltas
  for (size_t n = 0; n < list.size(); ++n) {
    auto closer = [&](int i) { return coarse[n * kCoarse + size_t(i)]; };
    auto blocked = [&](int i) { return closer(i) != kNoCloser; };
    // Blocked everywhere: closed. Blocked only next to the edge, free further out: a leg
    // grazing the edge's own face within rounding (seen 60 m from a wedge's apex), no gap.
    int free = 0;
    while (free < kCoarse && blocked(free)) ++free;
    if (free == kCoarse) {
      shapes[list[n].probe].width = -1.f;
      shapes[list[n].probe].closer = closer(0);
      continue;
    }
    int f = free;
    while (f < kCoarse && !blocked(f)) ++f;
    if (f == kCoarse) continue;  // free within reach: width 0
    gaps.push_back(list[n].probe);
    bracket.push_back({list[n].d[size_t(f - 1)], list[n].d[size_t(f)], closer(f)});
    below.emplace_back(list[n].d.begin() + free, list[n].d.begin() + f);
  }
  if (gaps.empty()) return;
  bracket = closedBelow(tracer, source, listener, probes, gaps, below, bracket);
  for (int r = 0; r < 2; ++r) bracket = refine(tracer, source, listener, probes, gaps, bracket);
  for (size_t n = 0; n < gaps.size(); ++n) {
    shapes[gaps[n]].width = std::sqrt(bracket[n].free * bracket[n].closed);
    shapes[gaps[n]].open = bracket[n].free;
    shapes[gaps[n]].closer = bracket[n].closer;
  }
}

/// Q's mouth may open onto a narrow gap that crosses the edge there: the slit between two
/// door leaves meeting under a lintel, where the lintel's point of least path length lies right
/// above it. Probed through that gap, Q looks free. For each path free at Q, the mouth kFlank
/// either side of Q along the edge (when both lie on the edge) decides instead: closed on both
/// sides, the edge is closed (what crosses it there is the crossing gap's own path); a gap on
/// both sides, the edge bounds that gap (the geometric mean of the two widths).
void probeFlanks(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
                 std::span<const GapProbe> probes, std::span<GapShape> shapes) {
  std::vector<GapProbe> flanks;
  std::vector<size_t> owner;
  for (size_t j = 0; j < probes.size(); ++j) {
    const GapProbe& g = probes[j];
    if (shapes[j].width != 0.f || !(g.reach > kGapNarrowest) || g.from > -kFlank || g.to < kFlank)
      continue;
    for (float a : {-kFlank, kFlank}) {
      GapProbe f = g;
      f.q += a * g.along;
      f.from -= a;
      f.to -= a;
      flanks.push_back(f);
    }
    owner.push_back(j);
  }
  if (flanks.empty()) return;
  std::vector<GapShape> found(flanks.size());
  findWidths(tracer, source, listener, flanks, found);
  for (size_t n = 0; n < owner.size(); ++n) {
    const float w0 = found[2 * n].width, w1 = found[2 * n + 1].width;
    if ((w0 < 0.f && w1 < 0.f) || (w0 > 0.f && w1 > 0.f)) {
      shapes[owner[n]].width = w0 < 0.f ? -1.f : std::sqrt(w0 * w1);
      shapes[owner[n]].closer = found[2 * n].closer;
    }
  }
}

/// Adds the kGapTestPoints points that tell whether gap j (its shape at Q) is still there at `a` m
/// along its edge from Q (valid: within the edge): free 0.5 w across the mouth or where Q's mouth
/// was found open (GapShape::open, when measured), blocked at 1.2 or 1.5 w.
void addGapTest(Round& round, size_t j, const GapProbe& g, const GapShape& shape, float a,
                bool valid = true) {
  const float w = shape.width;
  const glm::vec3 base = g.q + a * g.along;
  round.add(j, base + kInnerWidth * w * g.mouth, valid);
  round.add(j, base + shape.open * g.mouth, valid && shape.open > kInnerWidth * w);
  round.add(j, base + kMiddleWidth * w * g.mouth, valid);
  round.add(j, base + kOuterWidth * w * g.mouth, valid);
}

/// Whether test t of a round made by addGapTest found the gap (its points' closers).
bool gapTestHolds(const Round& round, const std::vector<uint32_t>& closer, size_t t) {
  const size_t k = kGapTestPoints * t;
  const bool open = closer[k] == kNoCloser || (round.valid[k + 1] && closer[k + 1] == kNoCloser);
  return round.valid[k] && open && (closer[k + 2] != kNoCloser || closer[k + 3] != kNoCloser);
}

/// For each gap, where it ends along its edge either side of Q: the edge's end when the gap is
/// still there just short of it, else bisection (kEndSteps) between Q and that end.
void findEnds(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
              std::span<const GapProbe> probes, const std::vector<size_t>& gaps,
              std::span<GapShape> shapes) {
  // Per gap and side: the last offset with the gap (lo) and the first without (hi), m.
  std::vector<std::array<float, 2>> lo(gaps.size(), {0.f, 0.f}), hi(gaps.size());
  for (size_t n = 0; n < gaps.size(); ++n)
    hi[n] = {probes[gaps[n]].from * 0.999f, probes[gaps[n]].to * 0.999f};
  for (int step = -1; step < kEndSteps; ++step) {
    // First the edge's ends themselves, then bisection; a side already settled is not probed.
    Round round;
    std::vector<std::array<size_t, 2>> side;  // per probed point pair: gap n, side
    std::vector<float> at;                    // its offset along the edge, m
    for (size_t n = 0; n < gaps.size(); ++n)
      for (size_t s = 0; s < 2; ++s) {
        if (step >= 0 && lo[n][s] == hi[n][s]) continue;
        at.push_back(step < 0 ? hi[n][s] : 0.5f * (lo[n][s] + hi[n][s]));
        side.push_back({n, s});
        addGapTest(round, gaps[n], probes[gaps[n]], shapes[gaps[n]], at.back());
      }
    if (at.empty()) break;
    const std::vector<uint32_t> closer = run(tracer, source, listener, probes, round);
    for (size_t i = 0; i < at.size(); ++i) {
      const auto [n, s] = side[i];
      const bool gap = gapTestHolds(round, closer, i);
      // Still there at the edge's end: it runs to the end (lo = hi there).
      (gap ? lo : hi)[n][s] = at[i];
      if (step < 0 && gap) hi[n][s] = at[i];
    }
  }
  for (size_t n = 0; n < gaps.size(); ++n) {
    GapShape& g = shapes[gaps[n]];
    g.from = lo[n][0];
    g.to = lo[n][1];
    // The slit's aspect is its whole length, not only what lies within kAlong widths of Q:
    // near the end of a leaf's edge Q has gap on one side only.
    g.aspect = std::max(g.aspect, std::min(float(2 * kAlong), (g.to - g.from) / g.width));
  }
}

/// For each channel gap (`channels`, depths measured), the surface across it halfway along its
/// depth: GapShape::closer. The first closed point across the mouth may be closed by a leg
/// meeting a face beyond the mouth (seen from off the axis, the wall's face round the reveal
/// hides the gap's far edge); the channel's far side is the reveal, and taking that face away
/// leaves the gap (engine/surface_bound.cpp).
void findFarSides(const Tracer& tracer, std::span<const GapProbe> probes,
                  const std::vector<size_t>& channels, std::span<GapShape> shapes) {
  std::vector<TraceRay> rays;
  for (size_t j : channels) {
    const GapProbe& g = probes[j];
    const glm::vec3 dir = g.through / glm::length(g.through);
    const glm::vec3 mid = g.q + (shapes[j].inset + 0.5f * shapes[j].depth) * dir;
    rays.push_back(TraceRay{mid, g.mouth, surfaceOffset(mid),
                            kOuterWidth * shapes[j].width + kGapProbeThrough});
  }
  std::vector<TraceHit> hits(rays.size());
  tracer.intersect(rays, hits);
  for (size_t n = 0; n < channels.size(); ++n)
    if (hits[n].found) shapes[channels[n]].closer = hits[n].surface.triangle;
}

/// For each channel gap, where its far side stands along the channel (GapShape::depth; returns
/// the channel gaps measured): rays
/// 1.5 widths across, from kGapProbeThrough outside either mouth toward the other; what they
/// run free before meeting it is not the gap's depth (a leaf 4 cm thick set in a 0.2 m reveal:
/// 0.04). A ray that meets nothing (the far side is the face's own body) leaves it whole. A ray
/// that starts inside the far side (a leaf standing a few millimetres proud of the wall, past
/// the mouth) meets the far side's face across the gap on its way back toward the edge (a
/// second ray, one width long): the far side stands from that mouth on.
std::vector<size_t> measureDepths(const Tracer& tracer, std::span<const GapProbe> probes,
                                  const std::vector<size_t>& gaps, std::span<GapShape> shapes) {
  constexpr size_t kRays = 4;  // per gap: along from either mouth, back across at either
  std::vector<TraceRay> rays;
  std::vector<size_t> owner;
  for (size_t j : gaps) {
    const GapProbe& g = probes[j];
    const float length = glm::length(g.through);
    if (!(length > 0.f)) continue;
    const glm::vec3 dir = g.through / length;
    const float w = shapes[j].width;
    const glm::vec3 front = g.q + kOuterWidth * w * g.mouth - kGapProbeThrough * dir;
    const glm::vec3 back = front + g.through + 2.f * kGapProbeThrough * dir;
    rays.push_back(TraceRay{front, dir, 0.f, length + kGapProbeThrough});
    rays.push_back(TraceRay{back, -dir, 0.f, length + kGapProbeThrough});
    rays.push_back(TraceRay{front, -g.mouth, 0.f, w});
    rays.push_back(TraceRay{back, -g.mouth, 0.f, w});
    owner.push_back(j);
  }
  if (rays.empty()) return owner;
  std::vector<TraceHit> hits(rays.size());
  tracer.intersect(rays, hits);
  for (size_t n = 0; n < owner.size(); ++n) {
    std::array<float, 2> free = {0.f, 0.f};  // from the front mouth, from the back one
    for (size_t k = 0; k < 2; ++k)
      if (hits[kRays * n + k].found && !hits[kRays * n + 2 + k].found)
        free[k] = std::max(0.f, hits[kRays * n + k].surface.t - kGapProbeThrough);
    GapShape& shape = shapes[owner[n]];
    const auto mine = hits.begin() + long(kRays * n);
    shape.farSide = std::any_of(mine, mine + long(kRays), [](const TraceHit& h) { return h.found; });
    shape.depth = std::max(0.f, glm::length(probes[owner[n]].through) - free[0] - free[1]);
    shape.inset = std::min(free[0], glm::length(probes[owner[n]].through) - shape.depth);
  }
  return owner;
}

}  // namespace

void probeGaps(const Tracer& tracer, const glm::vec3& source, const glm::vec3& listener,
               std::span<const GapProbe> probes, std::span<GapShape> shapes) {
  findWidths(tracer, source, listener, probes, shapes);
  probeFlanks(tracer, source, listener, probes, shapes);
  // Along the edge, 1 .. kAlong widths either side of Q: is there still a gap (free at half a
  // width across the mouth, or where Q's was found free) that closes within 1.5 widths? Tests
  // per probe: side, then offset.
  Round round;
  std::vector<size_t> gaps;
  for (size_t j = 0; j < probes.size(); ++j) {
    const float w = shapes[j].width;
    if (!(w > 0.f)) continue;
    gaps.push_back(j);
    for (int side = -1; side <= 1; side += 2)
      for (int i = 1; i <= kAlong; ++i) {
        const float a = float(side * i) * w;
        addGapTest(round, j, probes[j], shapes[j], a, a >= probes[j].from && a <= probes[j].to);
      }
  }
  if (gaps.empty()) return;
  const std::vector<uint32_t> closer = run(tracer, source, listener, probes, round);
  for (size_t n = 0; n < gaps.size(); ++n) {
    int run = 0;
    for (size_t side = 0; side < 2; ++side)
      for (size_t i = 0; i < kAlong && gapTestHolds(round, closer, (n * 2 + side) * kAlong + i);
           ++i)
        ++run;
    shapes[gaps[n]].aspect = float(run);
  }
  findEnds(tracer, source, listener, probes, gaps, shapes);
  findFarSides(tracer, probes, measureDepths(tracer, probes, gaps, shapes), shapes);
}

}  // namespace dpc
