#include "plugins/lv2/host.h"

#include <lv2/atom/atom.h>
#include <lv2/buf-size/buf-size.h>
#include <lv2/options/options.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace dpc::lv2 {

const Variant& variantOf(const char* uri) {
  for (const Variant& v : kVariants)
    if (uri && !std::strcmp(uri, v.uri)) return v;
  return kVariants[0];
}

int nominalBlockLength(LV2_URID_Map* map, const LV2_Feature* const* features) {
  if (!map) return 0;
  const LV2_URID key = map->map(map->handle, LV2_BUF_SIZE__nominalBlockLength);
  const LV2_URID atomInt = map->map(map->handle, LV2_ATOM__Int);
  for (int i = 0; features && features[i]; ++i) {
    if (std::strcmp(features[i]->URI, LV2_OPTIONS__options) != 0) continue;
    for (auto* o = static_cast<const LV2_Options_Option*>(features[i]->data); o && o->key; ++o)
      if (o->key == key && o->type == atomInt && o->size == sizeof(int32_t))
        return std::clamp(int(*static_cast<const int32_t*>(o->value)), 16, 8192);
  }
  return 0;
}

}  // namespace dpc::lv2
