// The warning every surface gives when the reflection order bound (propagation.max_order)
// ended rays that still carried a share of the emitted energy the decay needs: its bound and
// its one wording, shared by dpc-demo (offline and live), the C API's mirror of the bound and
// the Python module. Free of engine types, so any layer may include it.
#pragma once

#include <string>

namespace dpc {

/// The share of the emitted energy cut by max_order above which dpc-demo (live and offline) and
/// the Python module warn. In a diffuse room the energy still in flight when a ray ends is the
/// decay curve's level then (both fall as the room's energy does), so a share above -40 dB
/// cuts the decay off above the -35 dB where T30's fit ends. The C API's
/// DPC_MAX_ORDER_WARN_FRACTION mirrors it.
inline constexpr double kMaxOrderWarnFraction = 1e-4;

/// The max_order warning's text after its "where: " prefix, one line without a newline:
/// "propagation.max_order: rays ended at order N still carried X % of the emitted energy
/// (D dB, largest band): ...". `share` in (0, 1] (largest band, as kMaxOrderWarnFraction
/// bounds); `maxOrder` <= 0 when the caller does not know the order ("at their last order").
/// Allocates; any thread but the audio thread.
std::string maxOrderWarning(int maxOrder, double share);

}  // namespace dpc
