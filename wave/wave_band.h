// The wave band of one source: builds the grid of the scene's air, runs the solver
// (wave/fdtd.h) with a band-limited pulse and returns the pressure impulse response at each
// receiver at the audio sample rate, in the units of the ray-traced IR: a free-field path of
// length r is a band-limited Dirac of area 1 / (sqrt(4 pi) r), so its energy is the intensity
// 1 / (4 pi r^2) relative to the source's power, the energy response's scale (the solver's
// pressure 1 / (4 pi r) times sqrt(4 pi)). One simulation serves every receiver
// (the source is where the pulse enters; by reciprocity source and receiver may be swapped,
// docs/wave.md).
//
// Walls: one simulation per octave band up to the crossover (wave/wave_join.h's
// simulatedBands), each with the materials' admittance in that band (wave/admittance.h), split
// at the band edges by odd-order crossovers and summed (splitBand: the split is an allpass
// where the bands agree), so each octave decays with its own absorption.
// The pulse: a unit-area impulse through a causal 4th-order Butterworth low-pass at the maximum
// frequency (the grid's dispersion grows above it); the result is high-passed at kWaveDcHz
// (2nd order) to remove the pressure offset a closed room keeps after a volume of air was
// pushed into it. Causal: nothing precedes the direct sound but the pulse's own rise.
//
// Control thread (TBB workers inside); allocates the grid and the state (wave/wave_grid.h,
// about 14 bytes per node of the bounding box while building, 12 per node while simulating,
// 4 + 8 / N per node on each of N processes sharing the simulation);
// throws InputError naming the file and field for a source or receiver outside the air the
// grid reaches, and a grid beyond kMaxWaveNodes.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <span>
#include <string>
#include <vector>

#include "engine/geometry.h"
#include "engine/tracer.h"
#include "scene/scene.h"
#include "wave/fdtd.h"
#include "wave/wave_grid.h"

namespace dpc::wave {

/// Below this the wave band is high-passed (Hz): nothing a room plays lies lower.
inline constexpr double kWaveDcHz = 10.0;

/// A point the simulation needs, with the field that placed it (for the error message).
struct WavePoint {
  glm::vec3 position{0.f};
  std::string field;  ///< "sources[0].position", "listener.position", ...
};

struct WaveBandOptions {
  double seconds = 1.0;   ///< length of each IR
  int sampleRate = 48000; ///< of the IRs, Hz
  /// Called from the calling thread with (steps done, steps); may be empty.
  std::function<void(size_t, size_t)> progress;
  /// The processes sharing each simulation by slabs (wave/fdtd.h); null: this one alone.
  /// Every process gets the same IRs, bit for bit, whatever their number.
  SlabLink* link = nullptr;
  /// The air is flooded from the source alone. False: a receiver outside it (inside a solid,
  /// outside a closed mesh, in a room the source cannot reach) is an error (InputError naming
  /// the receiver and the source). True (a bake's probes): such a receiver gets no IR
  /// (WaveBand::reached 0, its IR zeros) instead.
  bool allowUnreached = false;
};

/// What a run cost and where its grid lay.
struct WaveBandStats {
  GridLayout layout;
  size_t airNodes = 0;
  size_t boundaryNodes = 0;
  int stepRate = 0;          ///< time steps per second
  size_t steps = 0;          ///< per simulation
  size_t simulations = 0;    ///< one per octave band up to the crossover
  size_t stateBytes =
      0;  ///< this process's solver arrays (its slab's pressure twice, the air mask, the boundary)
  double buildSeconds = 0.0; ///< wall time of the grid
  double simulateSeconds = 0.0;
  int processes = 1;         ///< sharing each simulation (options.link's size)
};

struct WaveBand {
  std::vector<std::vector<float>> irs;  ///< per receiver, options.sampleRate
  std::vector<uint8_t> reached;         ///< per receiver: 1 where it lies in the grid's air
  WaveBandStats stats;
};

/// The wave band of a source at `source` heard at `receivers`, for `scene`'s wave settings,
/// materials and speed of sound, over the geometry of `tracer` / `geometry` (built from it).
WaveBand simulateWaveBand(const SceneDesc& scene, const Tracer& tracer, const Geometry& geometry,
                          const WavePoint& source, std::span<const WavePoint> receivers,
                          const WaveBandOptions& options);

}  // namespace dpc::wave
