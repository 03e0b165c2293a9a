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
// Domain decomposition: processes sharing one simulation (an MPI job, apps/mpi/cluster.h) each
// update one slab of the grid's z slices and trade their edge slices with their neighbours
// every step (SlabLink). Each node's update reads the same values in the same order whatever
// the slab, and each receiver is read by one process, so any number of processes gives the
// same results bit for bit. Each process holds the pressure of its slab and the two slices
// around it only (pressureFloats), but still the whole grid (its air mask and boundary list,
// built on every process alike).
//
// Threads: simulate() runs on the calling thread with TBB workers over the slab's slices;
// allocates the two pressure arrays (pressureFloats each); no errors but those of
// allocation and of the SlabLink. Source: the scheme and its stability in S. Bilbao, Numerical
// Sound Synthesis (Wiley, 2009), ch. 10; the boundary as in wave/wave_grid.h.
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

/// The processes that share one simulation, as the solver needs them. Every process calls
/// each method at the same point of the same simulation (they are collectives).
class SlabLink {
 public:
  virtual ~SlabLink() = default;
  virtual int rank() const = 0;  ///< this process, 0 .. size() - 1
  virtual int size() const = 0;  ///< processes sharing the simulation
  /// Sends toLower to rank - 1 and toUpper to rank + 1 while receiving fromLower from rank - 1
  /// and fromUpper from rank + 1 (each span one z slice; empty where there is no neighbour).
  virtual void exchange(std::span<const float> toLower, std::span<float> fromLower,
                        std::span<const float> toUpper, std::span<float> fromUpper) = 0;
  /// Every process's `data` becomes what process `owner` holds.
  virtual void broadcast(std::span<float> data, int owner) = 0;
};

/// The z slices [first, last) (padded coordinates) that process `rank` of `ranks` updates:
/// the interior slices 1 .. dims - 2 in contiguous shares differing by at most one slice.
/// Throws std::invalid_argument when there are more processes than interior slices.
struct Slab {
  size_t first = 0, last = 0;
};
Slab slabOf(const GridLayout& layout, int rank, int ranks);

/// Floats in each of a process's two pressure arrays: its slab's slices and one more on
/// either side (the neighbours' edge slices it reads, or the padding).
size_t pressureFloats(const GridLayout& layout, const Slab& slab);

struct SimulationInput {
  double speedOfSound = 343.0;    ///< m/s
  int stepRate = 0;               ///< steps per second (stepRateFor)
  Stencil source;                 ///< where the volume acceleration enters
  std::span<const float> signal;  ///< q^n, m^3/s^2, one value per step (then 0)
  std::span<const Stencil> receivers;
  size_t steps = 0;
  /// Called after every step from the calling thread with (steps done, steps), so that a stop
  /// request it checks ends the run within one step; may be empty (callers throttle output).
  std::function<void(size_t, size_t)> progress;
  /// The processes sharing the simulation; null: this process updates every slice.
  SlabLink* link = nullptr;
};

/// Pressure at each receiver at times 0, T, 2T, ... (in.steps values; Pa per unit of the
/// signal's unit), from rest: the signal's value q^n enters at time n T. With in.link, every
/// process returns every receiver's values.
std::vector<std::vector<float>> simulate(const WaveGrid& grid, const SimulationInput& in);

}  // namespace dpc::wave
