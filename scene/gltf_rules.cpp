#include "scene/gltf_rules.h"

#include <cstring>

namespace dpc::gltf {

using nlohmann::json;

namespace {

constexpr ComponentType kComponentTypes[] = {{kByte, "BYTE", 1},
                                             {kUnsignedByte, "UNSIGNED_BYTE", 1},
                                             {kShort, "SHORT", 2},
                                             {kUnsignedShort, "UNSIGNED_SHORT", 2},
                                             {kUnsignedInt, "UNSIGNED_INT", 4},
                                             {kFloat, "FLOAT", 4}};

constexpr ElementType kElementTypes[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                         {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};

}  // namespace

const ComponentType* componentType(uint64_t code) {
  for (const ComponentType& c : kComponentTypes)
    if (uint64_t(c.code) == code) return &c;
  return nullptr;
}

std::string componentTypeList() {
  std::string out;
  for (const ComponentType& c : kComponentTypes)
    out += (out.empty() ? "(" : ", ") + std::to_string(c.code) + " " + c.name;
  return out + ")";
}

const ElementType* elementType(const std::string& name) {
  for (const ElementType& t : kElementTypes)
    if (name == t.name) return &t;
  return nullptr;
}

std::string Accessor::format() const {
  return std::string(type->name) + " of " + component->name + (normalized ? " (normalized)" : "");
}

bool Accessor::is(const char* typeName, int code) const {
  return std::strcmp(type->name, typeName) == 0 && component->code == code && !normalized;
}

const json& arrayAt(const Level& l, const json& obj, const std::string& field, const char* key,
                    size_t limit) {
  static const json kNone = json::array();
  const json* v = JsonReader::find(obj, key);
  if (!v) return kNone;
  const std::string f = join(field, key);
  if (!v->is_array()) l.r.fail(f, "expected an array, got " + JsonReader::describe(*v));
  if (v->size() > limit)
    l.r.fail(
        f, std::to_string(v->size()) + " entries, more than the limit of " + std::to_string(limit));
  return *v;
}

const json& objectAt(const Level& l, const json& arr, const std::string& field, size_t i) {
  l.r.expectObject(arr[i], index(field, i));
  return arr[i];
}

uint64_t integer(const Level& l, const json& v, const std::string& field, uint64_t min,
                 uint64_t max) {
  if (!v.is_number_unsigned())
    l.r.fail(field, "expected a whole number >= 0, got " + JsonReader::describe(v));
  const uint64_t x = v.get<uint64_t>();
  if (x < min || x > max)
    l.r.fail(field, std::to_string(x) + " is outside [" + std::to_string(min) + ", " +
                        std::to_string(max) + "]");
  return x;
}

uint64_t integerAt(const Level& l, const json& obj, const std::string& field, const char* key,
                   uint64_t min, uint64_t max, uint64_t fallback) {
  const json* v = JsonReader::find(obj, key);
  return v ? integer(l, *v, join(field, key), min, max) : fallback;
}

size_t indexValue(const Level& l, const json& v, const std::string& field, size_t count,
                  const char* array, const std::string& who) {
  if (!v.is_number_unsigned())
    l.r.fail(field,
             who + "expected an index (a whole number >= 0), got " + JsonReader::describe(v));
  const uint64_t i = v.get<uint64_t>();
  if (i >= count)
    l.r.fail(field, who + std::to_string(i) + " is not an index of " + array + " (" +
                        std::to_string(count) + (count == 1 ? " entry)" : " entries)"));
  return size_t(i);
}

std::optional<size_t> indexAt(const Level& l, const json& obj, const std::string& field,
                              const char* key, size_t count, const char* array,
                              const std::string& who) {
  const json* v = JsonReader::find(obj, key);
  if (!v) return std::nullopt;
  return indexValue(l, *v, join(field, key), count, array, who);
}

size_t requiredIndex(const Level& l, const json& obj, const std::string& field, const char* key,
                     size_t count, const char* array, const std::string& who) {
  const json* v = JsonReader::find(obj, key);
  if (!v) l.r.fail(join(field, key), who + "missing required key");
  return indexValue(l, *v, join(field, key), count, array, who);
}

std::vector<double> numbers(const Level& l, const json& v, const std::string& field, size_t count) {
  if (!v.is_array() || v.size() != count)
    l.r.fail(field, "expected an array of " + std::to_string(count) + " numbers, got " +
                        JsonReader::describe(v));
  std::vector<double> out;
  for (size_t i = 0; i < count; ++i) out.push_back(l.r.floatNumber(v[i], index(field, i)));
  return out;
}

std::string named(const json& entry, const char* kind) {
  const json* n = JsonReader::find(entry, "name");
  return n && n->is_string() ? std::string(kind) + " " + inQuotes(n->get<std::string>()) + ": "
                             : "";
}

}  // namespace dpc::gltf
