// The growth rule of the C API's versioned structs (include/dpc/dpc.h, "Versions and growth
// rule"): one table of the layouts each struct has had since 0.5.0, and the one pair of
// helpers every entry point uses to read a caller's struct of any known layout (the fields it
// lacks at their defaults) and to write one (only the fields it has).
#pragma once

#include <cstddef>
#include <cstring>
#include <iterator>
#include <span>

#include "dpc/dpc.h"

namespace dpc::api {

/// One layout of a versioned struct: its size in bytes and the releases that have it.
struct Layout {
  size_t size;
  const char* releases;
};

/// The layouts of versioned struct T, oldest first, the current one (sizeof(T)) last. An
/// earlier layout's size is the offset of the first field the next layout appended, so that
/// the table follows the struct; the test c_api_layout_test checks each size against the
/// released headers' layouts.
template <class T>
struct Layouts;

template <>
struct Layouts<dpc_engine_options> {
  static constexpr const char* kName = "dpc_engine_options";
  static constexpr Layout kKnown[] = {{offsetof(dpc_engine_options, ir_length), "0.5.0, 0.6.0"},
                                      {sizeof(dpc_engine_options), "0.7.0, 0.8.0, 0.9.0"}};
  /// The layout the plain dpc_engine_options_init of programs compiled against 0.6.0 fills.
  static constexpr size_t kPlainInitSize = kKnown[0].size;
};

template <>
struct Layouts<dpc_scene_data> {
  static constexpr const char* kName = "dpc_scene_data";
  static constexpr Layout kKnown[] = {
      {offsetof(dpc_scene_data, material_transmissions), "0.5.0, 0.6.0"},
      {offsetof(dpc_scene_data, estimator), "0.7.0"},
      {sizeof(dpc_scene_data), "0.8.0, 0.9.0"}};
  /// The layout the plain dpc_scene_data_init of programs compiled against 0.6.0 fills.
  static constexpr size_t kPlainInitSize = kKnown[0].size;
};

template <>
struct Layouts<dpc_stats> {
  static constexpr const char* kName = "dpc_stats";
  static constexpr Layout kKnown[] = {
      {offsetof(dpc_stats, input_samples_replaced), "0.5.0"},
      {offsetof(dpc_stats, dropped_energy_fraction), "0.6.0"},
      {offsetof(dpc_stats, max_order_energy_fraction), "0.7.0, 0.8.0"},
      {sizeof(dpc_stats), "0.9.0"}};
};

/// True when T's table obeys the rule: sizes increase, the last is sizeof(T), and each earlier
/// size is a multiple of T's alignment, i.e. the group appended after it starts at its sizeof
/// rather than inside its tail padding (where an old caller's size would not tell it apart).
template <class T>
constexpr bool grewAtItsEnd() {
  const auto& known = Layouts<T>::kKnown;
  for (size_t i = 0; i < std::size(known); ++i)
    if (known[i].size % alignof(T) != 0 || (i > 0 && known[i].size <= known[i - 1].size))
      return false;
  return known[std::size(known) - 1].size == sizeof(T);
}
static_assert(grewAtItsEnd<dpc_engine_options>() && grewAtItsEnd<dpc_scene_data>() &&
              grewAtItsEnd<dpc_stats>());

/// DPC_OK if `size` is in `known`; else DPC_ERR_VERSION with "NAME.struct_size: SIZE bytes is
/// not a layout this library (dpc X.Y.Z) knows: 160 (0.5.0), ..." as the thread's message.
/// Any thread; no allocation.
dpc_status checkLayout(const char* name, std::span<const Layout> known, size_t size);

/// Reads the caller's input struct: *full = `defaults` with the caller's first struct_size
/// bytes on top (struct_size then sizeof(T)), so that fields of later releases keep their
/// defaults. DPC_ERR_VERSION (nothing read past struct_size, *full unchanged) for an unknown
/// layout. Any thread; no allocation.
template <class T>
dpc_status readVersioned(const T* caller, const T& defaults, T* full) {
  const size_t size = caller->struct_size;
  if (const dpc_status s = checkLayout(Layouts<T>::kName, Layouts<T>::kKnown, size);
      s != DPC_OK)
    return s;
  *full = defaults;
  std::memcpy(static_cast<void*>(full), caller, size);
  full->struct_size = sizeof(T);
  return DPC_OK;
}

/// Writes `full` into the caller's output struct of `size` bytes (its struct_size becomes
/// `size`): the fields within it, nothing past it. DPC_ERR_VERSION (nothing written) for an
/// unknown layout. Any thread; no allocation.
template <class T>
dpc_status writeVersioned(T* out, size_t size, const T& full) {
  if (const dpc_status s = checkLayout(Layouts<T>::kName, Layouts<T>::kKnown, size);
      s != DPC_OK)
    return s;
  std::memcpy(static_cast<void*>(out), &full, size);
  out->struct_size = size;
  return DPC_OK;
}

}  // namespace dpc::api
