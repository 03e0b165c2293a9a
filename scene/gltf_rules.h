// What the glTF level checks (scene/gltf_check.h) share: the level being checked, what the
// earlier sections found in it, and typed reads of its JSON whose refusals name the field.
// Private to scene/gltf_check.cpp and scene/gltf_primitives.cpp.
//
// Any thread that loads a scene; allocates; throws InputError(level file, field, problem).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scene/gltf_check.h"
#include "scene/gltf_container.h"
#include "scene/json_reader.h"

namespace dpc::gltf {

/// glTF 2.0's accessor component types (componentType codes, as in OpenGL).
inline constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123,
                     kUnsignedInt = 5125, kFloat = 5126;

struct ComponentType {
  int code;
  const char* name;  ///< "UNSIGNED_SHORT"
  unsigned bytes;
};

struct ElementType {
  const char* name;  ///< "VEC3"
  unsigned components;
};

/// The component type of `code`, nullptr for a code glTF 2.0 does not define.
const ComponentType* componentType(uint64_t code);
/// "(5120 BYTE, 5121 UNSIGNED_BYTE, ...)", for messages.
std::string componentTypeList();
/// The element type named `name`, nullptr for a name glTF 2.0 does not define.
const ElementType* elementType(const std::string& name);

/// An accessor as the mesh and animation checks need it (its place is checked already).
struct Accessor {
  const ComponentType* component = nullptr;
  const ElementType* type = nullptr;
  uint64_t count = 0;
  bool normalized = false;
  bool bounds = false;  ///< min and max are given
  size_t view = 0;
  /// "VEC3 of SHORT (normalized)", for messages.
  std::string format() const;
  bool is(const char* typeName, int code) const;  ///< of that type and component, not normalized
};

struct View {
  size_t buffer = 0;
  uint64_t offset = 0, length = 0;
  uint64_t stride = 0;  ///< 0: tightly packed
};

/// The level being checked and what the sections checked so far found.
struct Level {
  explicit Level(const std::string& f) : file(f), r(f) {}
  std::string file;
  JsonReader r;
  GltfJson json;
  std::vector<uint64_t> bufferBytes;  ///< per buffer, its byteLength
  std::vector<View> views;
  std::vector<Accessor> accessors;
  std::vector<int64_t> parent;  ///< per node, its parent (-1: a root)
};

/// obj[key] as an array of at most `limit` entries (an empty one when absent).
const nlohmann::json& arrayAt(const Level& l, const nlohmann::json& obj, const std::string& field,
                              const char* key, size_t limit = kMaxGltfEntries);
/// arr[i], which must be an object; `field` names arr.
const nlohmann::json& objectAt(const Level& l, const nlohmann::json& arr, const std::string& field,
                               size_t i);
/// v as a whole number (a JSON integer, as glTF's schema says) within [min, max].
uint64_t integer(const Level& l, const nlohmann::json& v, const std::string& field, uint64_t min,
                 uint64_t max);
/// obj[key] as integer(), or `fallback` when absent.
uint64_t integerAt(const Level& l, const nlohmann::json& obj, const std::string& field,
                   const char* key, uint64_t min, uint64_t max, uint64_t fallback);
/// v as an index into `array`, which has `count` entries; `who` begins the message.
size_t indexValue(const Level& l, const nlohmann::json& v, const std::string& field, size_t count,
                  const char* array, const std::string& who = "");
/// obj[key] as an index into `array` of `count` entries; nullopt when absent.
std::optional<size_t> indexAt(const Level& l, const nlohmann::json& obj, const std::string& field,
                              const char* key, size_t count, const char* array,
                              const std::string& who = "");
/// obj[key] as an index into `array` of `count` entries; required.
size_t requiredIndex(const Level& l, const nlohmann::json& obj, const std::string& field,
                     const char* key, size_t count, const char* array, const std::string& who = "");
/// v as an array of `count` numbers, each finite and within float's range.
std::vector<double> numbers(const Level& l, const nlohmann::json& v, const std::string& field,
                            size_t count);
/// "mesh \"room\": " for an entry with a name (kind "mesh"), "" without, to begin messages.
std::string named(const nlohmann::json& entry, const char* kind);

/// meshes: primitives (modes, attributes, indices), their counts and triangles.
void checkMeshes(const Level& l);
/// animations: samplers and channels.
void checkAnimations(const Level& l);

}  // namespace dpc::gltf
