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
// A custom file: {"speakers": [{"name": "L", "azimuth": 30, "elevation": 0}, ...,
// {"name": "LFE", "lfe": true}]}, 2 .. kMaxLoudspeakers entries, azimuth in [-180, 180],
// elevation in [-90, 90], names unique, no two loudspeakers within 1 degree of each other.
//
// Control thread; allocates; throws InputError(file or "command line", field, ...).
#pragma once

#include <string>
#include <vector>

namespace dpc {

/// At most this many loudspeakers in a layout (a 64-channel dome).
inline constexpr size_t kMaxLoudspeakers = 64;

struct LoudspeakerDesc {
  std::string name;
  double azimuthDegrees = 0.0;
  double elevationDegrees = 0.0;
  bool lfe = false;  ///< low-frequency effects channel: left silent
};

/// The layout named by `spec`: "5.1", "7.1", "7.1.4" or a JSON file path. `flag` names the
/// option in errors about an unknown preset.
std::vector<LoudspeakerDesc> loudspeakerLayout(const std::string& spec, const std::string& flag);

}  // namespace dpc
