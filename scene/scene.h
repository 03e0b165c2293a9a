// Scene description, the data model: what a scene file (JSON + Wavefront OBJ) says, validated.
// Materials, meshes, sources, listeners, moving objects with their keyframes, and the
// propagation and audio settings, as plain structs and enumerations, with the fixed bounds on a
// scene's entity counts and the physical defaults. Its helpers live beside it:
// scene/trajectory.h (poses at a time, WorldState, evaluateWorld, teleports),
// scene/orientation.h (a listener's yaw, pitch and roll; a source's forward axis),
// scene/enum_names.h (the enumerations' names in scene files and on command lines),
// scene/tracing_policy.h (which end a frame traces from), scene/mesh_topology.h (welded
// vertices).
//
// Control thread: loadScene() reads files, allocates, and throws dpc::InputError (one line,
// "FILE: FIELD: problem") for anything a user got wrong: missing file, malformed JSON, wrong
// type, absorption outside [0, 1], NaN or infinite numbers, empty or fully degenerate mesh,
// unknown material, radius <= 0, and so on. The key-by-key format with units is
// docs/scene-format.md; the numeric ranges are one table (scene/limits.h) and one check
// (scene/validate.h), shared with the C API and the command lines. The readers are
// scene/scene_json.cpp and scene/obj_reader.h, the mesh cleaning scene/mesh_builder.h.
// Everything here is plain data: no Embree, no audio.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/bands.h"
#include "common/spherical_harmonics.h"
#include "scene/directivity.h"
#include "scene/loudspeaker_layout.h"

namespace dpc {

/// A surface material. absorption: energy absorption coefficient alpha per octave band,
/// in [0, 1] (ISO 354 sense); scattering: scattering coefficient s per octave band, in
/// [0, 1] (ISO 17497-1): the fraction of a band's reflected energy that leaves diffusely
/// (Lambert, cosine-weighted) rather than specularly. How the tracer honours per-band values
/// with one ray direction: ScatteringChoice (engine/geometry.h).
struct Material {
  std::string name;
  Bands absorption{0.1f};
  Bands scattering{0.5f};
  /// Transmission loss R per octave band, dB (scene/transmission.h); +infinity: opaque.
  Bands transmissionLossDb{std::numeric_limits<float>::infinity()};
};

/// Triangle mesh in metres, world coordinates (right-handed, y up by convention of the
/// shipped scenes; the engine does not care). Triangles index vertices; materialIndex[i]
/// indexes SceneDesc::materials for triangle i.
struct Mesh {
  std::vector<glm::vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<uint32_t> materialIndex;
};


struct Keyframe {
  double timeSeconds = 0.0;  ///< seconds from the start of the render, strictly increasing
  glm::vec3 position{0.f};   ///< metres
  /// Heading in degrees about the up (+y) axis: 0 faces +x, positive turns left
  /// (counter-clockwise seen from above). Either every keyframe has one or none does; with
  /// none the listener faces the walking direction.
  std::optional<float> yawDegrees;
  std::optional<float> pitchDegrees;  ///< degrees above the horizon (default 0)
  /// Degrees about the forward direction (default 0): positive tilts the head to its right,
  /// the right ear down (a right-hand turn about forward; aviation's roll).
  std::optional<float> rollDegrees;
  /// Sources only: orientation, a unit quaternion (glm stores w, x, y, z; the file gives
  /// [x, y, z, w] as glTF), slerped. Either every keyframe of a source has one or none does.
  std::optional<glm::quat> rotation;
  /// The point jumps here (a respawn, a cut): it stays at the previous keyframe's position
  /// until this keyframe's time instead of moving toward it, and its source-listener pairs
  /// start over at the jump (WorldState::sourceTeleports) instead of averaging across it.
  bool teleport = false;
};

struct SourceDesc {
  std::string name;
  glm::vec3 position{0.f};  ///< metres; used when the trajectory is empty
  std::string signalPath;   ///< dry WAV, resolved relative to the scene file's folder; empty: none
  float gainDb = 0.f;       ///< dB applied to the dry signal
  bool loop = false;        ///< repeat the dry signal for as long as the render lasts
  /// Position keyframes (yaw/pitch unused), linearly interpolated as the listener's; their
  /// rotations, when given, replace `rotation` (slerped, sourceRotationAt).
  std::vector<Keyframe> trajectory;
  bool trajectoryLoop = false;  ///< wrap time around the last keyframe ("trajectory_loop")
  /// Radiation pattern (scene/directivity.h); omni by default.
  Directivity directivity;
  /// Orientation: the forward axis of the directivity is rotation * (+x). Unit quaternion
  /// (glm order w, x, y, z); used when the trajectory's keyframes give none.
  glm::quat rotation{1.f, 0.f, 0.f, 0.f};
};

/// One pose keyframe of a moving object: world = R(rotation) * local + position.
struct ObjectKeyframe {
  double timeSeconds = 0.0;  ///< seconds, strictly increasing
  glm::vec3 position{0.f};   ///< metres, linearly interpolated
  /// Unit quaternion (glm stores w, x, y, z; the file gives [x, y, z, w] as glTF), slerped.
  glm::quat rotation{1.f, 0.f, 0.f, 0.f};
};

/// A moving rigid object: its own mesh in local coordinates (metres), materials from the
/// scene's `materials`, and a pose trajectory.
struct ObjectDesc {
  std::string name;
  std::string meshPath;                    ///< resolved relative to the scene file's folder
  Mesh mesh;                               ///< local coordinates
  std::vector<ObjectKeyframe> trajectory;  ///< at least one keyframe
  bool loop = false;                       ///< wrap time around the last keyframe
};

/// Rigid pose: world = rotation * local + position.
struct Pose {
  glm::vec3 position{0.f};
  glm::quat rotation{1.f, 0.f, 0.f, 0.f};
};

struct ListenerDesc {
  std::string name = "listener";     ///< unique among the scene's listeners
  glm::vec3 position{0.f};           ///< metres; used when the trajectory is empty
  float radius = 0.5f;               ///< receiver sphere radius, metres, > 0
  std::vector<Keyframe> trajectory;  ///< linear interpolation between keyframes
  bool loop = false;                 ///< wrap time around the last keyframe
  float yawDegrees = 0.f;    ///< heading when the trajectory gives none and there is no motion
  float pitchDegrees = 0.f;  ///< degrees above the horizon, when keyframes give none
  float rollDegrees = 0.f;   ///< head tilt about forward (Keyframe), when keyframes give none
};


/// Which estimator turns traced paths into the energy response.
enum class Estimator {
  kDpc,          ///< diffuse path cache (Schissler thesis, section 3.2.2)
  kPathTracing,  ///< plain Monte Carlo path tracing, no reuse between frames
};

/// Which end the rays leave from (engine/propagation.h, Propagator::setFromListeners). Both
/// give the same energy response in expectation (reciprocity); the cost of a frame is one
/// trace per emitter, so the fewer end is traced.
enum class Tracing {
  kAuto,           ///< from the listeners when there are more sources than listeners
  kFromSources,    ///< one trace per source, tested against every listener sphere
  kFromListeners,  ///< one trace per listener, tested against every source sphere
};

/// How a DPC entry's intensity is averaged over time (docs/estimators.md, "Its bias").
enum class DpcWeighting {
  kSeed,  ///< thesis eq. 3.2: I_hat / mu, mu = rays emitted since the entry was created
  kEma,   ///< unbiased: exponential moving average of per-frame estimates, time constant tau
  /// Unbiased: mean of the per-frame estimates over the last tau of frames (a sliding window,
  /// stored sparsely: only the frames that hit the entry). A change is answered fully after
  /// tau (docs/dynamic.md).
  kWindow,
};

/// Highest reflection order of exact specular paths (PropagationSettings::exactOrder): the
/// engine keeps a fixed array of this many triangles per path.
inline constexpr int kMaxExactOrder = 6;

/// Most tracing threads a run may ask for (PropagationSettings::threads: dpc-demo and dpc-bake
/// --threads, dpc.render's threads): more than the cores of any machine this runs on, far
/// below the 65537 at which TBB's task arena crashes.
inline constexpr int kMaxTracingThreads = 1024;

/// PropagationSettings::cachePoolMb's value for a pool sized by the scene ("auto" in JSON,
/// DPC_CACHE_POOL_AUTO in the C API): outside the field's range (0, 65536], so never a budget.
inline constexpr float kCachePoolAuto = -1.f;

struct PropagationSettings {
  int raysPerFrame = 4096;  ///< rays emitted per source per frame (N)
  int maxOrder = 200;       ///< maximum reflection order d_max
  float patchSize = 0.5f;   ///< lambda, metres
  float cacheTau = 1.0f;    ///< tau, seconds (0: no reuse)
  /// DPC memory budget per cache, i.e. per source-listener pair, megabytes (> 0). Beyond it
  /// the oldest entries are merged into a coarse store, never dropped (engine/path_cache.h).
  float cacheMemoryMb = 64.f;
  /// DPC memory budget of the whole engine, megabytes (> 0), or kCachePoolAuto (the default):
  /// sized by the scene's pairs, rays, tau and frame rate (cachePoolMbFor, engine/workload.h).
  /// Every pair's cache grows its tables from this one pool as its paths need room, up to
  /// cacheMemoryMb each (engine/cache_pool.h); beyond it pairs merge old paths (energy kept).
  float cachePoolMb = kCachePoolAuto;
  float frameRate = 15.f;  ///< propagation frames per second, Hz
  float irLength = 2.0f;   ///< impulse response length, seconds
  uint64_t seed = 1;       ///< random seed; the same seed gives bit-identical output
  Estimator estimator = Estimator::kDpc;
  DpcWeighting dpcWeighting = DpcWeighting::kWindow;  ///< default: docs/dynamic.md
  float speedOfSound = 343.f;                         ///< m/s
  float temperatureC = 20.f;     ///< air temperature, degrees Celsius (ISO 9613-1)
  float humidityPercent = 50.f;  ///< relative humidity, percent (ISO 9613-1)
  bool airAbsorption = true;     ///< apply ISO 9613-1 air absorption along paths
  /// First-order edge diffraction (UTD) of the direct sound around the static mesh's edges
  /// (engine/diffraction.h).
  bool diffraction = true;
  /// With diffraction: traced rays (and exact paths from the second order) off free-standing
  /// faces smaller than their Fresnel zone keep Rindel's share specular and scatter the rest
  /// (engine/reflection_scattering.h). Off: they reflect whole, as a wall does (quieter at equal
  /// rays where rays meet many small faces; docs/validation.md).
  bool reflectionScattering = true;
  /// Russian roulette: a ray whose band energy (with air attenuation) has fallen below this
  /// fraction of its initial energy in every band survives with probability
  /// kRouletteSurvival and, if it does, carries 1/kRouletteSurvival times its energy
  /// (unbiased). 0 disables it. Default -60 dB.
  float rouletteThreshold = 1e-6f;
  int threads = 0;  ///< tracing threads, 0 .. kMaxTracingThreads; 0 = all cores (command line only)
  /// Exact early specular paths (ray-guided image sources, engine/specular_paths.h): all-specular
  /// paths of up to this many reflections (0 .. kMaxExactOrder, and at most maxOrder) are found
  /// exactly and leave the energy response; the IR synthesis places them at their delays. 3 by
  /// default (the first reflections, heard as timbre, echoes and spaciousness). 0 disables the
  /// feature (the outputs are then those of an engine without it, bit for bit).
  int exactOrder = 3;
  /// Which end the rays leave from; kAuto picks the end with fewer points, so a frame costs
  /// one trace per listener when sources outnumber listeners (docs/performance.md, "Many
  /// sources"). The source spheres then have the listener's radius.
  Tracing tracing = Tracing::kAuto;
};

/// Output channels of the rendered IRs and audio.
enum class OutputFormat {
  kMono,      ///< one channel (the pressure IR)
  kStereo,    ///< two channels, constant-power panning of each arrival direction
  kBinaural,  ///< two channels (ears), HRTF from a SOFA file
  /// AmbiX: (order + 1)^2 channels, ACN order, SN3D normalisation (common/spherical_harmonics.h)
  kAmbisonics,
  /// One channel per loudspeaker of AudioSettings::speakers, VBAP per arrival (audio/vbap.h)
  kLoudspeakers,
  /// Two channels (ears): AmbiX IRs of ambisonicOrder synthesised in a fixed head frame,
  /// turned by the listener's head orientation on every audio block and decoded through the
  /// HRTF (audio/head_tracked_binaural.h). Head turns are heard without a new IR.
  kAmbisonicBinaural,
};

/// The binaural decoder of kAmbisonicBinaural (audio/ambisonic_binaural.h).
enum class BinauralDecoder {
  kMagLs,     ///< magnitude least squares above N c / (2 pi r) (the default)
  kSampling,  ///< virtual loudspeakers on a quadrature (kept for comparison)
};

/// Debian libmysofa1's MIT KEMAR set: the default HRTF.
inline constexpr const char* kDefaultHrtfPath = "/usr/share/libmysofa/default.sofa";

/// How the sources' impulse responses are rendered (runtime/hybrid_synthesis.h).
enum class Rendering {
  kAuto,       ///< hybrid when there are more sources than late buses, else per source
  kPerSource,  ///< every source's whole IR synthesised and convolved on its own
  /// Early part per source, late part per cluster of sources through a shared late bus.
  kHybrid,
};

struct AudioSettings {
  int sampleRate = 48000;  ///< Hz
  int blockSize = 512;     ///< samples per processing block
  OutputFormat output = OutputFormat::kMono;
  std::string hrtfPath = kDefaultHrtfPath;  ///< SOFA file for binaural output
  int ambisonicOrder = 3;                   ///< Ambisonic output's order N, 1 .. kMaxAmbisonicOrder
  /// Ambisonic output weighted per order by max-rE (a_n = P_n(r_E)); off: plain SN3D encoding.
  bool maxRe = false;
  /// kAmbisonicBinaural: how the AmbiX field is decoded to the ears.
  BinauralDecoder binauralDecoder = BinauralDecoder::kMagLs;
  /// kLoudspeakers: the layout (scene/loudspeaker_layout.h), one output channel each
  std::vector<LoudspeakerDesc> speakers;
  std::string layoutName;  ///< as given after "layout:" (preset name or file)
  Rendering rendering = Rendering::kAuto;
  /// Hybrid rendering: late buses (clusters of sources sharing a late IR) per listener.
  int lateBuses = 4;
  /// Hybrid rendering: a cluster's angular radius as seen from the listener, degrees.
  float clusterAngleDegrees = 30.f;
};

/// Grid nodes per wavelength at the wave band's maximum frequency: with the scheme of
/// wave/fdtd.h at its stability limit the phase speed is then at most 1.1 % slow (along the
/// grid's axes; exact along its diagonals), and 0.3 % at half that frequency (docs/wave.md).
inline constexpr double kWavePointsPerWavelength = 10.0;

/// The low band by wave simulation (wave/, docs/wave.md): a finite-difference time-domain
/// solution of the wave equation on a grid of the scene's air, below maxFrequencyHz, joined to
/// the ray-traced IR by power-complementary crossovers at crossoverHz. Off by default.
struct WaveSettings {
  bool enabled = false;
  /// Highest frequency the grid resolves with its stated dispersion error, Hz.
  float maxFrequencyHz = 500.f;
  /// Crossover between the wave band and the ray-traced band, Hz; 0: maxFrequencyHz / 2.
  float crossoverHz = 0.f;
  /// Grid spacing, metres; 0: from maxFrequencyHz (wave/wave_grid.h, kWavePointsPerWavelength).
  float gridSpacingM = 0.f;
  /// The crossover in use: crossoverHz, or half the maximum frequency when it is 0.
  float crossover() const { return crossoverHz > 0.f ? crossoverHz : 0.5f * maxFrequencyHz; }
  /// The largest grid spacing that resolves maxFrequencyHz at speed of sound c (m/s), metres.
  double maxSpacing(double c) const { return c / (double(maxFrequencyHz) * kWavePointsPerWavelength); }
  /// The grid spacing in use, metres: gridSpacingM, or maxSpacing(c) when it is 0.
  double spacing(double c) const { return gridSpacingM > 0.f ? double(gridSpacingM) : maxSpacing(c); }
  /// The field that sets spacing(): "wave.grid_spacing" when given, else "wave.max_frequency".
  const char* spacingField() const {
    return gridSpacingM > 0.f ? "wave.grid_spacing" : "wave.max_frequency";
  }
};

/// Upper bounds on a scene's entity counts, fixed (independent of the machine's memory) so a
/// scene either loads everywhere or nowhere; docs/scene-format.md "Limits" says why these values.
/// The limits table (scene/limits.h) bounds the counts with them.
inline constexpr size_t kMaxSources = 256;   ///< each source: its own IR, convolution and rays
inline constexpr size_t kMaxListeners = 64;  ///< each listener: an IR and convolution per source
inline constexpr size_t kMaxObjects = 256;   ///< each object: its own mesh and BVH instance

struct SceneDesc {
  std::string path;  ///< the scene file as given
  std::string meshPath;
  Mesh mesh;
  std::vector<Material> materials;
  std::vector<SourceDesc> sources;  ///< at least one
  std::vector<ObjectDesc> objects;  ///< moving rigid objects (may be empty)
  /// Every listener, at least one, unique names (from `listeners`, or `listener` alone);
  /// a listener is chosen by its index in this list.
  std::vector<ListenerDesc> listeners;
  PropagationSettings propagation;
  AudioSettings audio;
  WaveSettings wave;
  /// Things the loader repaired rather than refused (e.g. "hall.obj: 12 degenerate triangles
  /// dropped"); apps print them. Nothing is dropped without a line here.
  std::vector<std::string> warnings;
};

/// Reads a scene file and its meshes and validates them (scene/validate.h). Control thread;
/// allocates. Throws InputError naming the file and field on any problem.
SceneDesc loadScene(const std::string& path);

/// The index in scene.listeners of the listener named `name`. Throws InputError("command
/// line", flag, ...) listing the known names when there is none of that name. Any thread.
size_t listenerIndex(const SceneDesc& scene, const std::string& name, const std::string& flag);

/// The files a run of `scene` (loaded from `scenePath`) reads, each with what it is ("the
/// scene file", "the mesh", "a dry signal", "the loudspeaker layout", ...): the inputs no
/// output of the run may name.
std::vector<std::pair<std::string, std::string>> sceneInputFiles(const SceneDesc& scene,
                                                                 const std::string& scenePath);

}  // namespace dpc
