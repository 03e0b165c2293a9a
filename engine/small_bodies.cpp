#include "engine/small_bodies.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <limits>
#include <numbers>
#include <utility>

#include "engine/channel_path.h"
#include "engine/coherent_sum.h"
#include "engine/diffraction.h"
#include "engine/diffraction_edges.h"

namespace dpc {

namespace {

/// A group of flat surfaces for smallSurfaceBound: the surfaces (sorted), the largest extent
/// among those that stand free (m; freeStandingExtents) and the least path-length excess over
/// the direct distance of their edges' paths (m).
struct SmallGroup {
  std::vector<uint32_t> surfaces;
  float extent = 0.f;
  double excess = 1e30;
  /// m: its box's silhouette seen along the line of sight, its narrowest width (silhouetteWidth);
  /// infinite unless the group is a whole body or a closed solid (a wall's reveal is not thin).
  float across = std::numeric_limits<float>::infinity();
  bool whole = false;  ///< a whole body or a closed solid, standing free of the rest
};

/// The narrowest width (m) of the silhouette that the box round the surfaces casts along the
/// direction d (not zero): what shadows the sound passing it, a slat's thickness rather than its
/// depth. The silhouette is a convex polygon whose sides are the box's edges seen along d, and a
/// convex polygon is narrowest square to one of its sides: the box's width along each unit u
/// square to d and to an axis (sum_i |u_i| side_i), the least of the three.
float silhouetteWidth(const std::vector<uint32_t>& surfaces, const SurfaceBodies& bodies,
                      const glm::vec3& d) {
  const auto [lo, hi] = boxOfSurfaces(surfaces, bodies);
  const glm::vec3 side = hi - lo, n = glm::normalize(d);
  float least = std::numeric_limits<float>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    glm::vec3 e(0.f);
    e[axis] = 1.f;
    const glm::vec3 u = glm::cross(n, e);
    const float length = glm::length(u);
    if (length > 1e-6f) least = std::min(least, glm::dot(glm::abs(u / length), side));
  }
  return least;
}

/// How far apart two boxes stand (m): their separation along the axis that separates them most;
/// zero or less where they touch or overlap.
float boxesApart(const std::pair<glm::vec3, glm::vec3>& a,
                 const std::pair<glm::vec3, glm::vec3>& b) {
  const glm::vec3 gap = glm::max(a.first - b.second, b.first - a.second);
  return std::max({gap.x, gap.y, gap.z});
}

/// The most small bodies closeBodies gathers round those taken away before it gives up.
constexpr size_t kCloseBodiesMost = 64;

/// `removed` (sorted) with every other small body (not largeBody) whose box lies within `reach`
/// (m) of a body already in it added, again and again (the bodies of one screen or row, which
/// widestTogether then clusters); sorted. False when more than kCloseBodiesMost bodies would be
/// added (a louvre of more slats keeps no floor).
bool closeBodies(std::vector<uint32_t>& removed, const SurfaceBodies& bodies,
                 float reach = kChannelGapMax) {
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
  std::vector<bool> in(bodies.members.size(), false);
  for (uint32_t s : removed)
    if (s < bodies.body.size() && bodies.body[s] < in.size() && !in[bodies.body[s]]) {
      in[bodies.body[s]] = true;
      boxes.push_back(boxOfSurfaces(bodies.members[bodies.body[s]], bodies));
    }
  auto near = [&](const std::pair<glm::vec3, glm::vec3>& b) {
    return std::any_of(boxes.begin(), boxes.end(),
                       [&](const auto& a) { return boxesApart(a, b) <= reach; });
  };
  for (size_t added = 0, round = 0; round <= kCloseBodiesMost; ++round) {
    bool more = false;
    for (uint32_t b = 0; b < bodies.members.size(); ++b) {
      if (in[b] || bodies.members[b].empty() || largeBody(bodies, bodies.members[b][0])) continue;
      const auto box = boxOfSurfaces(bodies.members[b], bodies);
      if (!near(box)) continue;
      if (++added > kCloseBodiesMost) return false;
      in[b] = more = true;
      boxes.push_back(box);
      removed.insert(removed.end(), bodies.members[b].begin(), bodies.members[b].end());
    }
    if (!more) break;
  }
  std::sort(removed.begin(), removed.end());
  removed.erase(std::unique(removed.begin(), removed.end()), removed.end());
  return true;
}

/// The surfaces (sorted) and the small bodies close to them (closeBodies, within 3 cm or twice
/// the gaps `gap` (m) read between them: the next post of a row): the whole screen or row, which
/// a sum without them takes away (the edges of slats left beside those taken away, each summed
/// as an infinite edge's, would take the screen's slots for a screen's edges: a slat on the line
/// of sight between two 3 cm slots read 7.5 dB below the free field at 63 Hz, a slot beside two
/// slats left 7.9 dB, and posts left beside two rows of octagonal posts 3.5 dB above it); the
/// surfaces alone where closeBodies gives up.
std::vector<uint32_t> screenOf(const std::vector<uint32_t>& removed, const SurfaceBodies& bodies,
                               float gap) {
  std::vector<uint32_t> screen = removed;
  const float reach = std::isfinite(gap) ? std::max(kChannelGapMax, 2.f * gap) : kChannelGapMax;
  return closeBodies(screen, bodies, reach) ? screen : removed;
}

/// The surfaces taken away with free-standing surface s (sorted): its whole body when the body
/// is less than `wavelength` across (a seat's boxes, a box leaf: a small object goes whole), else
/// s alone (a leaf welded to its wall), a closed body's faces together (wholeSolids).
std::vector<uint32_t> smallGroupOf(uint32_t s, double wavelength, const SurfaceBodies& bodies) {
  const uint32_t b = bodies.body[s];
  if (b < bodies.members.size()) {
    const auto [lo, hi] = boxOfSurfaces(bodies.members[b], bodies);
    if (double(glm::distance(lo, hi)) < wavelength) return bodies.members[b];
  }
  return wholeSolids({s}, bodies);
}

/// Path p's small groups (smallGroupOf) into out, each with the least excess (m) it is given;
/// none that the line of sight crosses (q.crossed: those the blocked line of sight's bounds take
/// away).
void addSmallGroups(const EdgePath& p, double excess, const BoundQuery& q,
                    std::vector<SmallGroup>& out) {
  const double longest = q.speedOfSound / bandCentreExactHz(0);
  auto crossed = [&](uint32_t g) {
    return std::binary_search(q.crossed.begin(), q.crossed.end(), g);
  };
  for (uint32_t s : p.edge->surfaces) {
    if (s >= q.bodies.extent.size() || !(double(q.bodies.extent[s]) < longest)) continue;
    const auto known = std::find_if(out.begin(), out.end(), [&](const SmallGroup& g) {
      return std::binary_search(g.surfaces.begin(), g.surfaces.end(), s);
    });
    if (known != out.end()) {  // its group met already (a body's other edges)
      known->excess = std::min(known->excess, excess);
      continue;
    }
    std::vector<uint32_t> group = smallGroupOf(s, longest, q.bodies);
    if (std::any_of(group.begin(), group.end(), crossed)) continue;
    auto at = std::find_if(out.begin(), out.end(),
                           [&](const SmallGroup& g) { return g.surfaces == group; });
    if (at == out.end()) {
      float extent = 0.f;  // of the faces that stand free (a box's bottom on the floor does not)
      for (uint32_t g : group)
        if (std::isfinite(q.bodies.extent[g])) extent = std::max(extent, q.bodies.extent[g]);
      const uint32_t b = q.bodies.body[s];
      const bool whole = b < q.bodies.members.size() &&
                         (q.bodies.closed[b] || group == q.bodies.members[b]);
      const float across = whole ? silhouetteWidth(group, q.bodies, q.L - q.source)
                                 : std::numeric_limits<float>::infinity();
      at = out.insert(out.end(), SmallGroup{std::move(group), extent, 1e30, across, whole});
    }
    at->excess = std::min(at->excess, excess);
  }
}

/// The groups of free-standing flat surfaces smaller than the longest band's wavelength among the
/// paths' edges' faces (addSmallGroups), each with its paths' least excess (smallBands tests it
/// against the band's first Fresnel zone); and those of the hidden paths within the longest
/// band's first Fresnel zone, with no excess of their own (a slat behind another: taken away
/// with the rest by smallGroupsBound, whose sum would otherwise bring its edges back).
std::vector<SmallGroup> smallSurfaces(const std::vector<EdgePath>& paths, const BoundQuery& q) {
  const double longest = q.speedOfSound / bandCentreExactHz(0);
  const double direct = double(glm::distance(q.source, q.L));
  std::vector<SmallGroup> out;
  for (const EdgePath& p : paths)  // a path at its edge's end carries a slit's field only
    addSmallGroups(p, p.atEnd ? 1e30 : p.length - direct, q, out);
  if (out.empty()) return out;  // no small body's edge in the sum: nothing to hold
  for (const HiddenPath& h : q.hidden)
    if (!h.path.atEnd && h.path.length - direct < 0.5 * longest)
      addSmallGroups(h.path, 1e30, q, out);
  return out;
}

/// k a at most which a body whose silhouette is a wide (a half its narrowest width) counts as
/// thin: for the bounds above the sum, 1 (Rayleigh's limit); for the floors below it, 1/8, where
/// a slotted screen of such slats still passes the sound within about 2 dB (the mass law of its
/// slots' air, m' = rho d / sigma, at a third open and 4 cm deep: 3 dB at 250 Hz).
constexpr double kThinBound = 1.0, kThinFloor = 0.125;
/// k a at most which bodies with slots between them keep the slots' floor with the line of
/// sight blocked by them: under half a wavelength across (a half the width), no body casts a
/// geometric shadow, and what passes is the slots' (slotTransmission).
constexpr double kSlotFloor = 0.5 * std::numbers::pi;
/// Bands (63 Hz to 1 kHz) in which a group must be thin by kThinBound to be held in every band
/// (smallBands).
constexpr int kRowThinBands = 5;

/// The bands (the lowest ones) in which a silhouette `across` metres wide is thin: k a <= ka.
int thinBands(float across, float speedOfSound, double ka) {
  int bands = 0;
  while (bands < kNumBands &&
         std::numbers::pi * double(across) * bandCentreExactHz(bands) / speedOfSound <= ka)
    ++bands;
  return bands;
}

/// The bands (the lowest ones) in which bodies whose widest silhouette is `across` metres wide
/// keep a floor, with gaps `gap` (m) between them: none unless thin by kThinFloor in the lowest
/// band (slats, posts: a leaf shut against its stop is no row of slats, however thin the stop);
/// with slots (a finite gap) every band where they are under half a wavelength across
/// (kSlotFloor), without (bodies alone) those where they are thin by kThinFloor.
int floorBands(float across, float gap, float speedOfSound) {
  if (thinBands(across, speedOfSound, kThinFloor) == 0) return 0;
  return thinBands(across, speedOfSound, std::isfinite(gap) ? kSlotFloor : kThinFloor);
}

/// How close two bodies' boxes stand to be one silhouette (m): boards sealed to each other,
/// gaps under the probe's narrowest (0.5 mm, engine/gap_probe.h) up to 1 mm, make a solid screen
/// however thin each.
constexpr float kSealedGap = 1e-3f;

/// The widest silhouette (m, silhouetteWidth) among the surfaces (sorted) and the small bodies
/// close to them (closeBodies), each cluster of bodies within kSealedGap of each other one
/// silhouette: louvres' slats 1 cm apart and posts a hand apart are each their own (what passes
/// between them is slotTransmission's); infinity where closeBodies gives up.
float widestTogether(const std::vector<uint32_t>& removed, const BoundQuery& q) {
  std::vector<uint32_t> together = removed;
  if (!closeBodies(together, q.bodies)) return std::numeric_limits<float>::infinity();
  std::vector<std::vector<uint32_t>> clusters;  // surfaces
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
  for (uint32_t s : together) {
    const auto box = boxOfSurfaces({s}, q.bodies);
    std::vector<size_t> touching;
    for (size_t c = 0; c < clusters.size(); ++c)
      if (boxesApart(boxes[c], box) <= kSealedGap) touching.push_back(c);
    std::vector<uint32_t> merged = {s};
    std::pair<glm::vec3, glm::vec3> mergedBox = box;
    for (auto c = touching.rbegin(); c != touching.rend(); ++c) {
      merged.insert(merged.end(), clusters[*c].begin(), clusters[*c].end());
      mergedBox = {glm::min(mergedBox.first, boxes[*c].first),
                   glm::max(mergedBox.second, boxes[*c].second)};
      clusters.erase(clusters.begin() + long(*c));
      boxes.erase(boxes.begin() + long(*c));
    }
    clusters.push_back(std::move(merged));
    boxes.push_back(mergedBox);
  }
  float widest = 0.f;
  for (const std::vector<uint32_t>& c : clusters)
    widest = std::max(widest, silhouetteWidth(c, q.bodies, q.L - q.source));
  return widest;
}

/// The bands (the lowest ones) where a group's bound applies: it is small (its extent under the
/// wavelength, or its silhouette along the line of sight thin, thinBands with kThinBound: a slat
/// or a leaf seen edge on shadows no more than its thickness, a long body scatters per length
/// as its cross-section does) and, if `fresnel`, its least excess under half the wavelength (a
/// group farther out leaves the sum alone). Without `fresnel` (the groups together,
/// smallGroupsBound), a group thin up to kRowThinBands (a slat, a post, a rail: up to about
/// 11 cm across) is held in every band: above the bands where its bodies are thin, their edges'
/// first-order terms, each an infinite edge's and blind to the bodies beside it, still add up
/// in phase along a row of slats or posts (a slatted screen +3.4 / +12.5 dB re free field at 4
/// / 8 kHz with the line of sight through a slot, a grid of 5 cm posts +4.5 dB), while a row of
/// bodies passes at most what comes through between them. Such narrow faces' reflections are
/// exact paths or rays'; what the bound takes is at most the part of their reflection-boundary
/// terms above kLitRipple. Wider bodies (seats, furniture) keep their reflection-boundary terms.
int smallBands(const SmallGroup& group, float speedOfSound, bool fresnel = true) {
  const int thin = thinBands(group.across, speedOfSound, kThinBound);
  int bands = 0;
  while (bands < kNumBands) {
    const double wavelength = speedOfSound / bandCentreExactHz(bands);
    const bool small = double(group.extent) < wavelength || bands < thin;
    if (!small || (fresnel && !(group.excess < 0.5 * wavelength))) break;
    ++bands;
  }
  const bool row = thin >= kRowThinBands;
  return !fresnel && bands > 0 && row ? kNumBands : bands;
}

/// What the small groups are weighed against: all the paths, those kept without the surfaces
/// `base` and their band amplitudes (bandAmplitude), the coherent sum they give, and the slit
/// on the line of sight among the kept (slitOnLineOfSight; null if none), which stands in for
/// the direct sound in that sum.
struct SumParts {
  const std::vector<EdgePath>& paths;
  const std::vector<EdgePath>& kept;
  const std::vector<Bands>& amplitude;
  const Bands& sum;
  const EdgePath* throughSlit;
};

/// Whether the kept edge paths on the surfaces g (sorted) carry, in bands from .. to - 1, at
/// most kSmallShare of the sum's pressure: taking them away cannot move the sum past kLitRipple
/// either way, so no bound or floor holds it. Never where g holds a side of the slit the line
/// of sight passes: taking it away gives the direct sound back (a slatted screen seen through
/// a 3 mm slot read 27 dB below the free field at 63 Hz, its slats' own paths weak). With
/// `slits` (the line of sight free, where the row's bound holds the sum to what passes between
/// the bodies), never where a kept path on g carries a slit's field, which bandAmplitude does
/// not weigh (a louvre's slots beside the line of sight summed to 4.9 dB above the free field;
/// with the line of sight blocked by posts, the sum without their neighbours is nothing).
bool weakGroup(const SumParts& parts, const std::vector<uint32_t>& g, int from, int to,
               bool slits = false) {
  // (1 - s)^2 kLitRipple >= 1 for s <= 1 - 1 / sqrt(1.37) = 0.146.
  constexpr double kSmallShare = 0.14;
  auto in = [&](uint32_t s) { return std::binary_search(g.begin(), g.end(), s); };
  auto on = [&](const EdgePath& p) { return in(p.edge->surfaces[0]) || in(p.edge->surfaces[1]); };
  if (const EdgePath* slit = parts.throughSlit; slit && (on(*slit) || in(slit->gapCloser)))
    return false;
  if (slits && std::any_of(parts.kept.begin(), parts.kept.end(), [&](const EdgePath& p) {
        return p.gapWidth > 0.f && p.slitOwner && on(p);
      }))
    return false;
  for (int k = from; k < to; ++k) {
    double own = 0.0;
    for (size_t j = 0; j < parts.kept.size(); ++j)
      if (on(parts.kept[j])) own += double(parts.amplitude[j][k]);
    if (own > kSmallShare * std::sqrt(4.0 * std::numbers::pi * double(parts.sum[k]))) return false;
  }
  return true;
}

/// How far apart the boxes of flat surfaces s and t stand (m; their separation along the axis
/// that separates them most, 0 where they overlap or one is unknown).
float boxSeparation(const SurfaceBodies& bodies, uint32_t s, uint32_t t) {
  if (s >= bodies.box.size() || t >= bodies.box.size()) return 0.f;
  return std::max(0.f, boxesApart(bodies.box[s], bodies.box[t]));
}

/// The narrowest gap (m) that a slit path or a closed gap (q.closed) has with a surface in
/// `removed` (sorted) on either side: infinity where none has, 0 where such a gap is closed by
/// a surface not removed (a leaf shut in its frame: taking it away would open the doorway). A
/// gap read closed between two of the removed bodies, or between one and a small body standing
/// beside them (closeBodies: the next slat of the screen), counts as wide as their boxes stand
/// apart (posts in staggered rows whose silhouettes overlap along the line of sight, deep slats
/// seen at a slant, the bottom edge of a slat 3 cm from the next: the probes read the gap
/// between them closed); boards sealed to each other are bodiesTogether's.
float narrowestGap(const std::vector<EdgePath>& paths, const BoundQuery& q,
                   const std::vector<uint32_t>& removed) {
  auto in = [&](uint32_t s) { return std::binary_search(removed.begin(), removed.end(), s); };
  std::vector<uint32_t> beside;  // removed and the small bodies close to them, when first asked
  auto near = [&](uint32_t s) {
    if (beside.empty() && !closeBodies(beside = removed, q.bodies)) beside = removed;
    return std::binary_search(beside.begin(), beside.end(), s);
  };
  // A closed gap's closer lies at its mouth: a probe that met a body far from the edge (a ground
  // plane's rim 20 m off read closed by a slat) closes nothing near them.
  auto atMouth = [&](const EdgePath& p) {
    if (p.gapCloser >= q.bodies.box.size()) return true;
    const auto& [lo, hi] = q.bodies.box[p.gapCloser];
    const glm::vec3 reach(kChannelGapMax);
    return glm::all(glm::greaterThanEqual(p.q, lo - reach)) &&
           glm::all(glm::lessThanEqual(p.q, hi + reach));
  };
  float least = std::numeric_limits<float>::infinity();
  auto visit = [&](const EdgePath& p) {
    if (!(p.gapWidth > 0.f) && p.gapCloser == kUnknownSurface) return;
    const uint32_t s0 = p.edge->surfaces[0], s1 = p.edge->surfaces[1];
    if (!in(s0) && !in(s1) && !in(p.gapCloser)) return;
    if (!(p.gapWidth > 0.f) && !atMouth(p)) return;
    if (p.gapWidth > 0.f)
      least = std::min(least, p.gapWidth);
    else if (!((near(s0) || near(s1)) && near(p.gapCloser)))
      least = 0.f;
    else if (!onEdgeBody(q.bodies.body, *p.edge, p.gapCloser))  // closed between two of them:
      least = std::min(least, boxSeparation(q.bodies, s0, p.gapCloser));
  };
  std::for_each(paths.begin(), paths.end(), visit);
  std::for_each(q.closed.begin(), q.closed.end(), visit);
  return least;
}

/// The rows the groups (of surfaces) stand in along the line of sight (their boxes' extents
/// along it, merged where they overlap): each row's depth (m), as deep as its deepest group (a
/// row of posts across a slanted line of sight spans more along it than any post is deep).
std::vector<double> rowsAlongSight(const std::vector<std::vector<uint32_t>>& groups,
                                   const BoundQuery& q) {
  const glm::vec3 v = q.L - q.source;
  if (!(glm::length(v) > 0.f)) return {};
  const glm::vec3 n = glm::normalize(v), an = glm::abs(n);
  const int axis = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
  std::vector<std::array<double, 3>> spans;  // from, to, depth
  for (const std::vector<uint32_t>& g : groups) {
    const auto [lo, hi] = boxOfSurfaces(g, q.bodies);
    const double c = double(glm::dot(0.5f * (lo + hi), n));
    const double extent = double(glm::dot(an, hi - lo));  // the box's along the line
    // The slot's depth: the box's side along the axis nearest the line, over the cosine (a
    // slat's depth, not its height: the line rising 5 degrees adds none of its 2 m).
    const double depth = std::min(extent, double((hi - lo)[axis]) / double(an[axis]));
    spans.push_back({c - 0.5 * extent, c + 0.5 * extent, depth});
  }
  std::sort(spans.begin(), spans.end());
  std::vector<double> rows;
  double end = -std::numeric_limits<double>::infinity();
  for (const auto& [from, to, depth] : spans) {
    if (from > end) rows.push_back(0.0);
    rows.back() = std::max(rows.back(), depth);
    end = std::max(end, to);
  }
  return rows;
}

/// Per band, the power that rows of bodies (`groups` of surfaces) `across` wide with gaps `gap`
/// between them (m) pass at least, as slotted screens: each row a layer of its slots' air,
/// sigma = gap / (gap + across) open and d + 2 delta deep (d the row's depth, delta = gap / pi
/// ln(1 / sin(pi sigma / 2)) each mouth's end correction: Morse & Ingard, Theoretical
/// Acoustics, 9.4, slit gratings), passing a plane wave at normal incidence tau = 1 / (cos^2
/// kd + (sigma + 1 / sigma)^2 / 4 sin^2 kd) (a layer whose impedance is 1 / sigma the air's;
/// for k d << 1 the mass law of the slots' air, m' = rho d / sigma), the rows' in series
/// multiplied, averaged over the band's frequencies. 1 in every band without a gap (infinite),
/// 0 with a closed one.
Bands slotTransmission(const std::vector<std::vector<uint32_t>>& groups, double across, float gap,
                       const BoundQuery& q) {
  if (!std::isfinite(gap) || groups.empty()) return Bands(1.f);
  if (!(gap > 0.f)) return Bands(0.f);
  const double sigma = double(gap) / (double(gap) + across);
  const double delta =
      double(gap) / std::numbers::pi * std::log(1.0 / std::sin(0.5 * std::numbers::pi * sigma));
  const double a = 0.25 * (sigma + 1.0 / sigma) * (sigma + 1.0 / sigma);
  const std::vector<double> rows = rowsAlongSight(groups, q);
  Bands tau;
  for (int b = 0; b < kNumBands; ++b) {
    double mean = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double k = 2.0 * std::numbers::pi * diffractionFrequencyHz(b, i) / q.speedOfSound;
      double t = 1.0;
      for (double d : rows) {
        const double c = std::cos(k * (d + 2.0 * delta)), s = std::sin(k * (d + 2.0 * delta));
        t /= c * c + a * s * s;
      }
      mean += t / kDiffractionFrequenciesPerBand;
    }
    tau[b] = float(mean);
  }
  return tau;
}

/// The small groups smallGroupsBound takes away from band k on (those whose bands, smallBands,
/// reach past k): their surfaces with `base` (sorted), each group's surfaces, the widest
/// silhouette among them (m), the first band where one of them stops (n), and whether every one
/// is a whole body (`free` with a floor asked for).
struct BandGroups {
  std::vector<uint32_t> removed;
  std::vector<std::vector<uint32_t>> listed;
  double across = 0.0;
  int n = kNumBands;
  bool free = true;
};

BandGroups bandGroups(const std::vector<SmallGroup>& groups, const std::vector<int>& bands, int k,
                      const std::vector<uint32_t>& base, bool floor) {
  BandGroups g{base, {}, 0.0, kNumBands, floor};
  for (size_t i = 0; i < groups.size(); ++i) {
    if (bands[i] <= k) continue;
    g.listed.push_back(groups[i].surfaces);
    g.across = std::max(g.across, double(groups[i].across));
    g.free = g.free && groups[i].whole;
    g.removed.insert(g.removed.end(), groups[i].surfaces.begin(), groups[i].surfaces.end());
    g.n = std::min(g.n, bands[i]);
  }
  std::sort(g.removed.begin(), g.removed.end());
  g.removed.erase(std::unique(g.removed.begin(), g.removed.end()), g.removed.end());
  return g;
}

/// The small groups together (smallSurfaces, smallBands): in each band, at most kLitRipple times
/// the sum without every group small in it, into bound, and (`floor` not null) at least that sum
/// over kLitRipple, into *floor. Small bodies scatter weakly, together as each alone, while
/// their edges' first-order terms, each an infinite edge's, add up in phase where their path
/// excesses are short (a slatted screen's slats read 18 dB above the free field at 63 Hz with
/// the line of sight free, one group at a time the others holding the excess), or take a thin
/// slat's near edge for a screen's (10 dB below the free field 1 cm beside it). Groups outside
/// the first Fresnel zone go too: the bound is on all of them together. The floor needs them all
/// standing free, none closed to another surface (narrowestGap), and thin together as each alone;
/// what passes between them is held at their slots' mass law (slotTransmission).
void smallGroupsBound(const SumParts& parts, const DirectSound& coherent,
                      const std::vector<SmallGroup>& groups, const std::vector<uint32_t>& base,
                      BoundQuery& q, Bands& bound, Bands* floor) {
  std::vector<int> bands;
  for (const SmallGroup& g : groups) bands.push_back(smallBands(g, q.speedOfSound, false));
  for (int k = 0; k < kNumBands;) {  // bands k .. n - 1 take away the same groups
    const BandGroups g = bandGroups(groups, bands, k, base, floor != nullptr);
    const size_t count = g.listed.size();
    const float gap = g.free ? narrowestGap(parts.paths, q, g.removed) : 0.f;
    int thin = floorBands(float(g.across), gap, q.speedOfSound);  // the floor's bands
    const bool free = g.free && count > 0 && thin > k && gap > 0.f;
    if (count == 0 || (count == 1 && !free)) return;  // one alone: smallSurfaceBound's own
    if (weakGroup(parts, g.removed, k, g.n, coherent.visible)) {
      k = g.n;
      continue;
    }
    if (free) thin = std::min(thin, floorBands(widestTogether(g.removed, q), gap, q.speedOfSound));
    const Bands without = sumWithout(
        parts.paths, q, free && thin > k ? screenOf(g.removed, q.bodies, gap) : g.removed, coherent,
        g.n);
    const Bands tau = free ? slotTransmission(g.listed, g.across, gap, q) : Bands(0.f);
    for (int b = k; b < g.n; ++b) {
      bound[b] = std::min(bound[b], kLitRipple * without[b]);
      if (free && b < thin)
        (*floor)[b] = std::min(without[b], coherent.intensity[b]) * tau[b] / kLitRipple;
    }
    k = g.n;
  }
}

/// The bodies a blocked line of sight's floor takes away (thinBodiesFloor): the groups it
/// crosses and the thin bodies beside them (a slat the line of sight crosses has gaps to its
/// neighbours, and together they are the screen), each group's silhouette width (m).
struct FloorBodies {
  std::vector<uint32_t> removed;  // sorted
  std::vector<std::vector<uint32_t>> groups;
  std::vector<float> across;
};

/// Fills f; false when a body the line of sight crosses does not stand free (a whole body or a
/// closed solid), or none is found.
bool gatherFloorBodies(const std::vector<EdgePath>& paths, BoundQuery& q, FloorBodies& f) {
  const double longest = q.speedOfSound / bandCentreExactHz(0);
  int n = kNumBands;
  for (uint32_t s : q.crossed) {
    if (s >= q.bodies.body.size() || q.bodies.body[s] >= q.bodies.members.size()) return false;
    const uint32_t b = q.bodies.body[s];
    std::vector<uint32_t> group = smallGroupOf(s, longest, q.bodies);
    if (!q.bodies.closed[b] && group != q.bodies.members[b]) return false;  // not standing free
    f.across.push_back(silhouetteWidth(group, q.bodies, q.L - q.source));
    n = std::min(n, thinBands(f.across.back(), q.speedOfSound, kThinFloor));
    f.removed.insert(f.removed.end(), group.begin(), group.end());
    f.groups.push_back(std::move(group));
  }
  for (const SmallGroup& g : smallSurfaces(paths, q))
    if (g.whole && thinBands(g.across, q.speedOfSound, kThinFloor) >= std::max(n, 1)) {
      f.removed.insert(f.removed.end(), g.surfaces.begin(), g.surfaces.end());
      f.groups.push_back(g.surfaces);
      f.across.push_back(g.across);
    }
  std::sort(f.removed.begin(), f.removed.end());
  f.removed.erase(std::unique(f.removed.begin(), f.removed.end()), f.removed.end());
  return !f.groups.empty();
}

}  // namespace

Bands smallSurfaceBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                        const Bands& sum, BoundQuery& q, const std::vector<uint32_t>& base) {
  Bands bound(1e30f);
  const std::vector<EdgePath> kept =
      base.empty() ? paths : pathsWithout(paths, q, base, coherent.visible);
  const std::vector<SmallGroup> groups = smallSurfaces(kept, q);
  int most = 0;  // with the groups out of the first Fresnel zone (smallGroupsBound's)
  for (const SmallGroup& group : groups)
    most = std::max(most, smallBands(group, q.speedOfSound, false));
  std::vector<Bands> amplitude(kept.size(), Bands(0.f));  // each path's, once
  for (size_t j = 0; j < kept.size(); ++j)
    for (int k = 0; k < most; ++k)
      amplitude[j][k] = float(bandAmplitude(kept[j], k, q.speedOfSound));
  const SumParts parts{paths, kept, amplitude, sum,
                       coherent.visible ? slitOnLineOfSight(kept, q.source, q.L) : nullptr};
  for (const SmallGroup& group : groups) {
    const int bands = smallBands(group, q.speedOfSound);
    if (bands == 0 || weakGroup(parts, group.surfaces, 0, bands)) continue;
    std::vector<uint32_t> removed = base;
    removed.insert(removed.end(), group.surfaces.begin(), group.surfaces.end());
    std::sort(removed.begin(), removed.end());
    removed.erase(std::unique(removed.begin(), removed.end()), removed.end());
    const Bands without = sumWithout(paths, q, removed, coherent, bands);
    for (int k = 0; k < bands; ++k) bound[k] = std::min(bound[k], kLitRipple * without[k]);
  }
  const bool floor = coherent.visible && base.empty();
  if (floor) q.smallFloor = Bands(0.f);
  smallGroupsBound(parts, coherent, groups, base, q, bound, floor ? &q.smallFloor : nullptr);
  return bound;
}

Bands thinBodiesFloor(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                      const Bands& free, BoundQuery& q) {
  Bands floor(0.f);
  FloorBodies f;
  if (coherent.visible || !gatherFloorBodies(paths, q, f)) return floor;
  const float gap = narrowestGap(paths, q, f.removed);
  if (!(gap > 0.f)) return floor;
  double widest = 0.0;  // m
  for (float across : f.across) widest = std::max(widest, double(across));
  const int n = std::min(floorBands(float(widest), gap, q.speedOfSound),
                         floorBands(widestTogether(f.removed, q), gap, q.speedOfSound));
  if (n == 0) return floor;
  DirectSound open = coherent;
  open.visible = true;
  open.intensity = free;
  const Bands without = sumWithout(paths, q, screenOf(f.removed, q.bodies, gap), open, n);
  const Bands tau = slotTransmission(f.groups, widest, gap, q);
  for (int k = 0; k < n; ++k) floor[k] = std::min(free[k], without[k]) * tau[k] / kLitRipple;
  return floor;
}

}  // namespace dpc
