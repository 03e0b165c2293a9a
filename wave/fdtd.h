// The wave band's solver: the standard rectilinear finite-difference time-domain scheme for
// the wave equation p_tt = c^2 lap p + c^2 q(t) delta(x - x_s) on a WaveGrid (7-point
// Laplacian, leapfrog in time), with locally reacting walls of real normalised admittance
// beta (finite-volume boundary nodes), a point source of volume acceleration q (m^3/s^2) and
// pressure receivers, both trilinear between the eight nodes around them.
//
// Time step: the Courant number sum_a (c T / h_a)^2 = kCourantSquared, just inside the
// stability limit 1 (lambda = 1/sqrt 3 on a cubic grid). At the limit the scheme has no
// dispersion along the grid's diagonals and its largest along the axes: phase speed
// 1.1 % slow at 10 nodes per wavelength, 0.3 % at 20 (kWavePointsPerWavelength).
// Boundary node update (K open faces, g = c T / 2 * sum over closed faces of beta / h_a):
//   (1 + g) p^{n+1} = 2 p^n - (1 - g) p^{n-1} + sum_open (c T / h_a)^2 (p_nb - p^n).
// Free field: a pulse q(t) of unit area gives p(r, t) = q(t - r / c) / (4 pi r) (c^2 q delta
// injected as T^2 c^2 q^n / (h_x h_y h_z) at the source's nodes).
//
// Threads: simulate() runs on the calling thread with TBB workers over the grid's slices;
// allocates the two pressure arrays (8 bytes per array node); no errors but those of
// allocation. Source: the scheme and its stability in S. Bilbao, Numerical Sound Synthesis
// (Wiley, 2009), ch. 10; the boundary as in wave/wave_grid.h.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <optional>
#include <span>
#include <vector>

#include "wave/wave_grid.h"

namespace dpc::wave {

/// sum_a (c T / h_a)^2: 0.999 of the stability limit (a margin for rounding; at exactly 1 the
/// highest mode of the grid would be marginally stable).
inline constexpr double kCourantSquared = 0.999;

/// Time steps per second for `layout` at speed of sound c (m/s): the smallest whole number of
/// Hz at or above the Courant limit's rate.
int stepRateFor(const GridLayout& layout, double c);

/// Trilinear weights of the air nodes around a point (those in the solid get none, the rest
/// sum to 1).
struct Stencil {
  std::array<uint32_t, 8> index{};
  std::array<float, 8> weight{};
};

/// The stencil of point p (metres), or nothing when none of its eight nodes is air.
std::optional<Stencil> stencilAt(const WaveGrid& grid, const glm::vec3& p);

struct SimulationInput {
  double speedOfSound = 343.0;    ///< m/s
  int stepRate = 0;               ///< steps per second (stepRateFor)
  Stencil source;                 ///< where the volume acceleration enters
  std::span<const float> signal;  ///< q^n, m^3/s^2, one value per step (then 0)
  std::span<const Stencil> receivers;
  size_t steps = 0;
  /// Called now and then from the calling thread with (steps done, steps); may be empty.
  std::function<void(size_t, size_t)> progress;
};

/// Pressure at each receiver at times 0, T, 2T, ... (in.steps values; Pa per unit of the
/// signal's unit), from rest: the signal's value q^n enters at time n T.
std::vector<std::vector<float>> simulate(const WaveGrid& grid, const SimulationInput& in);

}  // namespace dpc::wave
