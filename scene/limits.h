// The limits of a scene's numeric fields: one table, read by validate() (scene/validate.h), by
// the scene-file reader, the C API, the command-line overrides of dpc-demo and dpc-bench, by
// the tests that feed every entry point each limit, and checked against docs/scene-format.md.
//
// Everything here is constant data and pure functions: any thread, no allocation except the
// strings returned, no errors except lookups of a field that is not in the table.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>

namespace dpc {

/// One bounded field. `field` is its path in a scene file with "[]" for any array index and
/// "*" for any material name ("propagation.cache_tau", "sources[].gain_db",
/// "materials.*.absorption"); the `listeners[i]` fields share the `listener.` entries, and
/// "position" bounds every coordinate (positions, keyframes, mesh vertices). Counts of array
/// entries ("sources") are fields too. A value v is accepted when min <= v <= max (min < v when
/// minExclusive) and, for integer fields, v is a whole number. max may be +infinity: no upper
/// bound for finite values (a non-finite value is never accepted).
struct Limit {
  std::string_view field;
  double min;
  double max;
  bool minExclusive;
  bool integer;
  std::string_view unit;  ///< SI or customary unit ("s", "Hz", "dB"); empty for pure numbers
  std::string_view why;   ///< the reason for the bounds, for people reading the table
};

/// Every limit, in the order of docs/scene-format.md.
std::span<const Limit> limits();

/// The entry of `field`. Throws std::logic_error for a field that is not in the table (a
/// programming error: callers name fields from this table).
const Limit& limitOf(std::string_view field);

/// True when `value` lies within the limit (NaN and infinities never do).
bool withinLimit(const Limit& limit, double value);

/// The range as docs/scene-format.md writes it: "[16000, 192000]", "(0, 60]", "> 0", ">= 0".
std::string rangeText(const Limit& limit);

/// A value as the error messages print it: whole numbers without a fraction ("48000"), others
/// in the shortest form that reads back as the same float ("1.7").
std::string valueText(double value);

/// What is wrong with `value` for `limit`, as every entry point words it: "VALUE is outside
/// RANGE UNIT", "VALUE must be RANGE UNIT" for a range without upper bound, or "VALUE is not an
/// integer"; "" when the value is within the limit. Written NUL-terminated (truncated) into
/// out[0..size) without allocating, for entry points that may not allocate (the C API's
/// wait-free setters); size >= 1. Any thread.
void writeLimitProblem(const Limit& limit, double value, char* out, size_t size);

/// True when each coordinate (m) lies within the "position" limit: the one check of a point
/// entering the scene at run time (host poses) before it can reach Embree. Any thread; no
/// allocation.
bool positionWithinLimit(float x, float y, float z);

}  // namespace dpc
