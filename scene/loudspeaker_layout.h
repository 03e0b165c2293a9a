// Loudspeaker layouts for `--output layout:NAME|FILE.json`: the presets 5.1, 7.1 and 7.1.4
// and custom files.
//
// Presets (channel order as WAV's WAVEFORMATEXTENSIBLE / SMPTE ST 2036-2 order; angles from
// ITU-R BS.775 for 5.1 and ITU-R BS.2051 for 7.1 (System I, 0+7+0) and 7.1.4 (System J,
// 4+7+0), taking one value where the standards give a range):
//   5.1:   L 30, R -30, C 0, LFE, Ls 110, Rs -110 (elevation 0)
//   7.1:   L 30, R -30, C 0, LFE, Lrs 135, Rrs -135, Lss 90, Rss -90
//   7.1.4: 7.1 + Ltf 45/30, Rtf -45/30, Ltr 135/30, Rtr -135/30 (azimuth/elevation)
// Azimuth counter-clockwise from the front (positive left), elevation up, degrees.
// A custom file: {"speakers": [{"name": "L", "azimuth": 30, "elevation": 0, "distance": 2.5},
// ..., {"name": "LFE", "lfe": true}]}, 2 .. kMaxLoudspeakers entries, azimuth in [-180, 180],
// elevation in [-90, 90], names unique, no two loudspeakers within 1 degree of each other;
// "distance" (metres from the listening position, [kMinLoudspeakerDistance,
// kMaxLoudspeakerDistance]) on every loudspeaker that is not LFE, or on none.
//
// Distance compensation of an irregular layout (the practice of room calibration, e.g.
// ITU-R BS.1116-3 section 8.4 / BS.2051: every loudspeaker's sound arrives at the listening
// position at the same time and level): loudspeaker i at distance d_i of the farthest d_max
// is fed delayed by (d_max - d_i) / c and scaled by d_i / d_max (the inverse-distance law of
// its own path, which the nearer loudspeaker has less of).
//
// Control thread; allocates; throws InputError(file or "command line", field, ...).
#pragma once

#include <string>
#include <vector>

namespace dpc {

/// At most this many loudspeakers in a layout (a 64-channel dome).
inline constexpr size_t kMaxLoudspeakers = 64;
/// Loudspeaker distances a layout file may give, metres (a headphone-close near field to a
/// large installation; the compensating delay is at most 100 m / c, about 0.3 s).
inline constexpr double kMinLoudspeakerDistance = 0.1;
inline constexpr double kMaxLoudspeakerDistance = 100.0;

struct LoudspeakerDesc {
  std::string name;
  double azimuthDegrees = 0.0;
  double elevationDegrees = 0.0;
  bool lfe = false;  ///< low-frequency effects channel: left silent
  /// Metres from the listening position; 0: not given (the layout is not compensated).
  double distanceMetres = 0.0;
};

/// How one loudspeaker's feed is compensated for its distance (see the file comment).
struct DistanceCompensation {
  size_t delaySamples = 0;  ///< (d_max - d_i) / c at the sample rate, rounded
  double gain = 1.0;        ///< d_i / d_max (amplitude)
};

/// Per loudspeaker of `layout` (LFE and layouts without distances: no delay, gain 1);
/// speedOfSound m/s, sampleRate Hz. Any thread; allocates the result.
std::vector<DistanceCompensation> distanceCompensation(const std::vector<LoudspeakerDesc>& layout,
                                                       double speedOfSound, int sampleRate);

/// The layout named by `spec`: "5.1", "7.1", "7.1.4" or a JSON file path. `flag` names the
/// option in errors about an unknown preset.
std::vector<LoudspeakerDesc> loudspeakerLayout(const std::string& spec, const std::string& flag);

}  // namespace dpc
