// The one validation of a scene's values: every bounded field against the limits table
// (scene/limits.h) and the rules between fields. The scene-file reader, the C API, and the
// command-line overrides of dpc-demo and dpc-bench all call these, so a value is accepted or
// refused the same way whichever door it comes through.
//
// Control thread (any thread that owns the SceneDesc); allocates only for error messages;
// throws InputError with one line "ORIGIN: FIELD: problem", FIELD spelled as the entry point's
// user wrote it (a JSON path, a struct member, a flag).
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "scene/scene.h"

namespace dpc {

/// Where values come from: `name` is the scene file's path as given, "dpc_scene_data",
/// "dpc_engine_options" or "command line". `spell` maps a field's scene-file path
/// ("propagation.cache_tau", "sources[2].gain_db", "listeners[0].radius",
/// "materials.wood.absorption[3]", "mesh.vertices[7][1]") to the name the user wrote
/// ("--tau", "cache_tau"); without it the path is the name.
struct Origin {
  std::string name;
  std::function<std::string(const std::string& path)> spell;

  /// The field as this origin's user knows it.
  std::string fieldName(const std::string& path) const;
};

/// Origin "command line": the flags of dpc-demo and dpc-bench that override scene keys
/// (--rays, --max-order, --tau, --cache-memory-mb, --frame-rate, --block-size) spell their
/// key; other fields keep their path.
Origin commandLineOrigin();

/// Throws InputError(origin.name, origin.fieldName(path), "VALUE is outside RANGE UNIT", or
/// "VALUE must be > MIN" for a range without upper bound, or "VALUE is not an integer") unless
/// `value` lies within limitOf(field). `path` is the concrete place (with indices and names);
/// it defaults to `field`. Throws std::logic_error if `field` is not in the table.
void checkField(std::string_view field, double value, const Origin& origin,
                const std::string& path = "");

/// The single-precision value a float field holds for `written`, checked as held: as
/// checkField, and besides, when only the rounding takes it out of range or turns a nonzero
/// value into 0 (which can mean "automatic" or "off": wave.grid_spacing, cache_tau), throws
/// InputError "WRITTEN rounds to HELD in single precision[: problem]" naming the value as the
/// user wrote it (`writtenText`; default "%g" of `written`).
float checkFloatField(std::string_view field, double written, const Origin& origin,
                      const std::string& path = "", const std::string& writtenText = "");

/// Throws InputError(origin.name, origin.fieldName(field), "N FIELD, more than the limit of
/// MAX" or "..., fewer than the minimum of MIN") unless `count` entries of the array `field`
/// ("sources", "listeners", "objects") lie within its limit.
void checkCount(const char* field, size_t count, const Origin& origin);

/// Throws InputError(origin.name, origin.fieldName(field), ...) for an empty `name` or one
/// holding control characters (names are printed in messages and warnings, and become port
/// names), or, when `namesFile` (a listener's name is part of output file names), a '/'.
void checkName(const std::string& name, bool namesFile, const Origin& origin,
               const std::string& field);

/// Checks every field of `scene` against the limits table and the rules between fields:
/// at least one material; entity counts; unique, non-empty source, listener and object names
/// without control characters (and without '/' in a listener's, which names output files);
/// keyframe times >= 0 and strictly increasing, yaw on every listener keyframe or on none;
/// every object with a keyframe; a mesh with triangles whose vertex and material indices are
/// in range and whose coordinates are within the coordinate limit. The linear
/// rouletteThreshold is not checked here: its table entry is in dB and is checked where a dB
/// value is read. Throws InputError naming origin and field for the first problem found.
void validate(const SceneDesc& scene, const Origin& origin);

}  // namespace dpc
