#include "wave/fdtd.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dpc::wave {
namespace {

/// The scheme's coefficients: (c T / h_a)^2 per axis and c T / 2.
struct Coefficients {
  std::array<float, 3> lambda2{};
  float halfCT = 0.f;
  float sourceScale = 0.f;  ///< T^2 c^2 / (h_x h_y h_z), 1/m
};

Coefficients coefficientsFor(const GridLayout& g, double c, int stepRate) {
  const double t = 1.0 / double(stepRate);
  Coefficients k;
  for (int a = 0; a < 3; ++a) k.lambda2[size_t(a)] = float(std::pow(c * t / g.spacing[a], 2));
  k.halfCT = float(0.5 * c * t);
  k.sourceScale = float(t * t * c * c / (g.spacing.x * g.spacing.y * g.spacing.z));
  return k;
}

/// What one process of a simulation updates and reads: its slab, its part [boundaryBegin,
/// boundaryEnd) of the boundary list (in array order, so a slab's nodes are contiguous), and
/// which process reads each receiver (the one whose slab holds its stencil's lowest slice).
struct Share {
  Slab slab;
  size_t plane = 0;  ///< floats per z slice
  /// The pressure arrays hold slices slab.first - 1 .. slab.last (the slab and the neighbours'
  /// edge slices it reads): array index n of the grid is element n - base of them.
  size_t base = 0;
  size_t boundaryBegin = 0, boundaryEnd = 0;
  std::vector<int> receiverOwner;
  int rank = 0;
};

Share shareOf(const WaveGrid& grid, const SimulationInput& in) {
  Share sh;
  const auto d = grid.layout.dims();
  const int ranks = in.link ? in.link->size() : 1;
  sh.rank = in.link ? in.link->rank() : 0;
  sh.slab = slabOf(grid.layout, sh.rank, ranks);
  sh.plane = d[0] * d[1];
  sh.base = (sh.slab.first - 1) * sh.plane;
  auto before = [&](size_t slice) {
    return size_t(std::lower_bound(grid.boundary.begin(), grid.boundary.end(), slice * sh.plane,
                                   [](const BoundaryNode& b, size_t i) { return b.index < i; }) -
                  grid.boundary.begin());
  };
  sh.boundaryBegin = before(sh.slab.first);
  sh.boundaryEnd = before(sh.slab.last);
  for (const Stencil& r : in.receivers) {
    const size_t slice = std::clamp<size_t>(r.index[0] / sh.plane, 1, d[2] - 2);
    int owner = 0;
    while (slabOf(grid.layout, owner, ranks).last <= slice) ++owner;
    sh.receiverOwner.push_back(owner);
  }
  return sh;
}

/// Next values of boundary nodes [b0, b1) (from p = p^n and q = p^{n-1}, whose element 0 is
/// the grid's array index `base`) into next[b - b0].
void boundaryStep(const WaveGrid& grid, const Coefficients& k, size_t b0, size_t b1, size_t base,
                  const float* p, const float* q, std::vector<float>& next) {
  const auto d = grid.layout.dims();
  const std::array<size_t, 3> stride{1, d[0], d[0] * d[1]};
  for (size_t b = b0; b < b1; ++b) {
    const BoundaryNode& node = grid.boundary[b];
    const size_t n = node.index - base;
    float lap = 0.f;
    for (int face = 0; face < 6; ++face) {
      if (!(node.openFaces & (1u << face))) continue;
      const size_t s = stride[size_t(face / 2)];
      lap += k.lambda2[size_t(face / 2)] * ((face % 2 ? p[n + s] : p[n - s]) - p[n]);
    }
    const float g = k.halfCT * node.admittancePerMetre;
    next[b - b0] = (2.f * p[n] - (1.f - g) * q[n] + lap) / (1.f + g);
  }
}

/// The interior update over every node of slices [k0, k1): q becomes p^{n+1}, zero off the
/// air (boundary nodes are overwritten afterwards). p and q start at the grid's index `base`.
void interiorStep(const WaveGrid& grid, const Coefficients& k, size_t base, const float* p,
                  float* q, size_t k0, size_t k1) {
  const auto d = grid.layout.dims();
  const size_t sy = d[0], sz = d[0] * d[1];
  const float lx = k.lambda2[0], ly = k.lambda2[1], lz = k.lambda2[2];
  const float centre = 2.f - 2.f * (lx + ly + lz);
  const float* air = grid.air.data();
  for (size_t kk = k0; kk < k1; ++kk)
    for (size_t j = 1; j + 1 < d[1]; ++j) {
      const size_t row = sy * j + sz * kk;
      const float* a = air + row;
      const float* pr = p + (row - base);
      float* qr = q + (row - base);
      for (size_t i = 1; i + 1 < d[0]; ++i)
        qr[i] = a[i] * (centre * pr[i] - qr[i] + lx * (pr[i - 1] + pr[i + 1]) +
                        ly * (pr[i - sy] + pr[i + sy]) + lz * (pr[i - sz] + pr[i + sz]));
    }
}

/// The stencil's pressure from p, whose element 0 is the grid's index `base`.
float sample(const Stencil& s, size_t base, const float* p) {
  float v = 0.f;
  for (size_t c = 0; c < 8; ++c) v += s.weight[c] * p[s.index[c] - base];
  return v;
}

/// One step of the share's nodes: q (p^{n-1}) becomes p^{n+1}, the signal's q^n entering at
/// the source's nodes in the slab.
void advance(const WaveGrid& grid, const Coefficients& k, const Share& sh,
             const SimulationInput& in, size_t n, const float* p, float* q,
             std::vector<float>& next) {
  boundaryStep(grid, k, sh.boundaryBegin, sh.boundaryEnd, sh.base, p, q, next);
  tbb::parallel_for(tbb::blocked_range<size_t>(sh.slab.first, sh.slab.last), [&](const auto& r) {
    interiorStep(grid, k, sh.base, p, q, r.begin(), r.end());
  });
  for (size_t b = sh.boundaryBegin; b < sh.boundaryEnd; ++b)
    q[grid.boundary[b].index - sh.base] = next[b - sh.boundaryBegin];
  if (n >= in.signal.size()) return;
  for (size_t c = 0; c < 8; ++c) {
    const size_t slice = in.source.index[c] / sh.plane;
    if (slice >= sh.slab.first && slice < sh.slab.last)
      q[in.source.index[c] - sh.base] += k.sourceScale * in.source.weight[c] * in.signal[n];
  }
}

/// Refreshes the slices next to the slab (p's lowest and highest neighbours' edge slices).
void tradeEdges(SlabLink& link, const Share& sh, float* p) {
  const bool lower = sh.rank > 0, upper = sh.rank + 1 < link.size();
  auto slice = [&](size_t k) { return std::span<float>(p + k * sh.plane - sh.base, sh.plane); };
  link.exchange(lower ? slice(sh.slab.first) : std::span<float>(),
                lower ? slice(sh.slab.first - 1) : std::span<float>(),
                upper ? slice(sh.slab.last - 1) : std::span<float>(),
                upper ? slice(sh.slab.last) : std::span<float>());
}

}  // namespace

int stepRateFor(const GridLayout& layout, double c) {
  double inverse2 = 0.0;
  for (int a = 0; a < 3; ++a) inverse2 += 1.0 / (layout.spacing[a] * layout.spacing[a]);
  return int(std::ceil(c * std::sqrt(inverse2 / kCourantSquared)));
}

std::optional<Stencil> stencilAt(const WaveGrid& grid, const glm::vec3& p) {
  const GridLayout& g = grid.layout;
  std::array<size_t, 3> base{};
  std::array<double, 3> frac{};
  for (int a = 0; a < 3; ++a) {
    // Padded coordinate of p: node i sits at (i - 1/2) spacings from the box's corner.
    const double u = (double(p[a]) - g.boundsMin[a]) / g.spacing[a] + 0.5;
    if (!(u >= 0.0 && u <= double(g.count[size_t(a)]) + 1.0)) return std::nullopt;
    base[size_t(a)] = std::min(size_t(u), size_t(g.count[size_t(a)]));
    frac[size_t(a)] = u - double(base[size_t(a)]);
  }
  Stencil s;
  double total = 0.0;
  for (size_t c = 0; c < 8; ++c) {
    const size_t i = base[0] + (c & 1), j = base[1] + ((c >> 1) & 1), k = base[2] + (c >> 2);
    s.index[c] = uint32_t(g.index(i, j, k));
    const double w = (c & 1 ? frac[0] : 1.0 - frac[0]) * ((c >> 1) & 1 ? frac[1] : 1.0 - frac[1]) *
                     (c >> 2 ? frac[2] : 1.0 - frac[2]);
    s.weight[c] = float(w * double(grid.air[s.index[c]]));
    total += double(s.weight[c]);
  }
  if (!(total > 1e-6)) return std::nullopt;
  for (float& w : s.weight) w = float(double(w) / total);
  return s;
}

Slab slabOf(const GridLayout& layout, int rank, int ranks) {
  const size_t interior = layout.dims()[2] - 2;
  if (ranks < 1 || size_t(ranks) > interior)
    throw std::invalid_argument("the wave grid has " + std::to_string(interior) +
                                " z slices, fewer than the " + std::to_string(ranks) +
                                " processes sharing its simulation (mpirun -np)");
  return {1 + interior * size_t(rank) / size_t(ranks),
          1 + interior * size_t(rank + 1) / size_t(ranks)};
}

size_t pressureFloats(const GridLayout& layout, const Slab& slab) {
  const auto d = layout.dims();
  return (slab.last - slab.first + 2) * d[0] * d[1];
}

std::vector<std::vector<float>> simulate(const WaveGrid& grid, const SimulationInput& in) {
  const Coefficients k = coefficientsFor(grid.layout, in.speedOfSound, in.stepRate);
  const Share sh = shareOf(grid, in);
  std::vector<float> p(pressureFloats(grid.layout, sh.slab), 0.f), q(p.size(), 0.f);
  std::vector<float> next(sh.boundaryEnd - sh.boundaryBegin);
  std::vector<std::vector<float>> out(in.receivers.size(), std::vector<float>(in.steps, 0.f));
  for (size_t n = 0; n < in.steps; ++n) {
    if (in.link) tradeEdges(*in.link, sh, p.data());
    // p holds p^n, the pressure at time n T (at rest for n = 0).
    for (size_t r = 0; r < in.receivers.size(); ++r)
      if (sh.receiverOwner[r] == sh.rank) out[r][n] = sample(in.receivers[r], sh.base, p.data());
    if (n + 1 < in.steps) advance(grid, k, sh, in, n, p.data(), q.data(), next);
    std::swap(p, q);
    if (in.progress) in.progress(n + 1, in.steps);
  }
  if (in.link)
    for (size_t r = 0; r < out.size(); ++r) in.link->broadcast(out[r], sh.receiverOwner[r]);
  return out;
}

}  // namespace dpc::wave
