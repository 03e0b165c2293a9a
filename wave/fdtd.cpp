#include "wave/fdtd.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

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

/// Next values of the boundary nodes (from p = p^n and q = p^{n-1}) into `next`.
void boundaryStep(const WaveGrid& grid, const Coefficients& k, const float* p, const float* q,
                  std::vector<float>& next) {
  const auto d = grid.layout.dims();
  const std::array<size_t, 3> stride{1, d[0], d[0] * d[1]};
  for (size_t b = 0; b < grid.boundary.size(); ++b) {
    const BoundaryNode& node = grid.boundary[b];
    const size_t n = node.index;
    float lap = 0.f;
    for (int face = 0; face < 6; ++face) {
      if (!(node.openFaces & (1u << face))) continue;
      const size_t s = stride[size_t(face / 2)];
      lap += k.lambda2[size_t(face / 2)] * ((face % 2 ? p[n + s] : p[n - s]) - p[n]);
    }
    const float g = k.halfCT * node.admittancePerMetre;
    next[b] = (2.f * p[n] - (1.f - g) * q[n] + lap) / (1.f + g);
  }
}

/// The interior update over every node of slices [k0, k1): q becomes p^{n+1}, zero off the
/// air (boundary nodes are overwritten afterwards).
void interiorStep(const WaveGrid& grid, const Coefficients& k, const float* p, float* q,
                  size_t k0, size_t k1) {
  const auto d = grid.layout.dims();
  const size_t sy = d[0], sz = d[0] * d[1];
  const float lx = k.lambda2[0], ly = k.lambda2[1], lz = k.lambda2[2];
  const float centre = 2.f - 2.f * (lx + ly + lz);
  const float* air = grid.air.data();
  for (size_t kk = k0; kk < k1; ++kk)
    for (size_t j = 1; j + 1 < d[1]; ++j) {
      const size_t row = sy * j + sz * kk;
      for (size_t i = row + 1; i < row + d[0] - 1; ++i)
        q[i] = air[i] * (centre * p[i] - q[i] + lx * (p[i - 1] + p[i + 1]) +
                         ly * (p[i - sy] + p[i + sy]) + lz * (p[i - sz] + p[i + sz]));
    }
}

float sample(const Stencil& s, const float* p) {
  float v = 0.f;
  for (size_t c = 0; c < 8; ++c) v += s.weight[c] * p[s.index[c]];
  return v;
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

std::vector<std::vector<float>> simulate(const WaveGrid& grid, const SimulationInput& in) {
  const Coefficients k = coefficientsFor(grid.layout, in.speedOfSound, in.stepRate);
  std::vector<float> p(grid.layout.arraySize(), 0.f), q(p.size(), 0.f), next(grid.boundary.size());
  std::vector<std::vector<float>> out(in.receivers.size(), std::vector<float>(in.steps, 0.f));
  const size_t slices = grid.layout.dims()[2];
  for (size_t n = 0; n < in.steps; ++n) {
    boundaryStep(grid, k, p.data(), q.data(), next);
    tbb::parallel_for(tbb::blocked_range<size_t>(1, slices - 1), [&](const auto& r) {
      interiorStep(grid, k, p.data(), q.data(), r.begin(), r.end());
    });
    for (size_t b = 0; b < grid.boundary.size(); ++b) q[grid.boundary[b].index] = next[b];
    if (n < in.signal.size())
      for (size_t c = 0; c < 8; ++c)
        q[in.source.index[c]] += k.sourceScale * in.source.weight[c] * in.signal[n];
    // q holds p^{n+1}, the pressure at time (n + 1) T; out[r][0] is the field at rest.
    if (n + 1 < in.steps)
      for (size_t r = 0; r < in.receivers.size(); ++r)
        out[r][n + 1] = sample(in.receivers[r], q.data());
    std::swap(p, q);
    if (in.progress && (n % 256 == 255 || n + 1 == in.steps)) in.progress(n + 1, in.steps);
  }
  return out;
}

}  // namespace dpc::wave
