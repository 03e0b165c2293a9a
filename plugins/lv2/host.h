// What an instance learns from the bundle and the host before it loads a scene: which of the
// bundle's plugins it is (its outputs and the output format it forces on scenes) and the
// host's nominal block length. Instantiation thread; no allocation.
#pragma once

#include <lv2/core/lv2.h>
#include <lv2/urid/urid.h>

#include <iterator>

#include "dpc/dpc.h"

namespace dpc::lv2 {

/// One plugin of the bundle (plugins/lv2/CMakeLists.txt writes its Turtle): its outputs are
/// the second and third ports, then the ports after the controls
/// (index 13, 14, ...: plugins/lv2/CMakeLists.txt)
struct Variant {
  const char* uri;
  int outputs;                ///< audio output ports
  dpc_output_format output;   ///< forced on every scene; DPC_OUTPUT_SCENE: the scene's
  int ambisonicOrder;         ///< DPC_OUTPUT_AMBISONICS: the order, (order + 1)^2 = outputs
};
constexpr Variant kVariants[] = {
    {"urn:dpc:lv2:room", 2, DPC_OUTPUT_SCENE, 0},
    {"urn:dpc:lv2:room-ambix1", 4, DPC_OUTPUT_AMBISONICS, 1},
    {"urn:dpc:lv2:room-ambix3", 16, DPC_OUTPUT_AMBISONICS, 3},
};
constexpr int kMaxOutputs = 16;

/// The variant whose URI is `uri` (the descriptor's); the stereo plugin if none matches.
const Variant& variantOf(const char* uri);

/// The host's bufsz:nominalBlockLength (an atom:Int among the LV2 options), clamped to the
/// engine block's range [16, 8192]; 0 if the host gives none (or no URID map to read it).
int nominalBlockLength(LV2_URID_Map* map, const LV2_Feature* const* features);

}  // namespace dpc::lv2
