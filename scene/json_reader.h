// Typed reads out of a parsed scene JSON (nlohmann::json), each refusal an InputError naming
// the file and the dotted field. Private to scene/ (the JSON type stays behind dpc_scene).
//
// Control thread; allocates; throws InputError.
#pragma once

#include <cstdint>
#include <filesystem>
#include <glm/vec3.hpp>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace dpc {

std::string inQuotes(const std::string& s);
/// "parent.key", or "key" at the top level.
std::string join(const std::string& parent, const std::string& key);
/// "parent[i]".
std::string index(const std::string& parent, size_t i);
/// `p` relative to `folder` unless absolute, normalised.
std::filesystem::path resolve(const std::filesystem::path& folder, const std::string& p);

/// Throws InputError(file, "", "JSON nested deeper than 64 levels at line N") when `text`
/// nests arrays/objects deeper than kMaxJsonDepth: JSON parsers recurse once per level, so the
/// depth is bounded before parsing that a hostile file cannot overflow the stack. Any thread.
void checkJsonDepth(const std::string& file, const std::string& text);

/// Reads and parses a JSON file (at most kMaxSceneBytes, nested at most kMaxJsonDepth, no
/// object repeating a key), reporting malformed JSON with line and column. `what` names the
/// kind of file in the messages about the file itself ("scene file", "layout file").
nlohmann::json parseJsonFile(const std::string& file, const std::string& what = "scene file");

/// Parses `text`, the JSON of `file`, under parseJsonFile's rules (depth, no repeated key,
/// malformed JSON reported with line and column), refusing more than `maxValues` values
/// (objects, arrays, numbers, strings, literals) before the next one is built.
nlohmann::json parseJsonText(const std::string& file, const std::string& text,
                             size_t maxValues = std::numeric_limits<size_t>::max());

/// Reads typed values out of the parsed JSON, throwing InputError(file, field, ...) on any
/// mismatch. Keys starting with '_' are comments and ignored everywhere.
class JsonReader {
 public:
  using json = nlohmann::json;

  explicit JsonReader(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const std::string& field, const std::string& problem) const;

  void expectObject(const json& v, const std::string& field) const;

  /// Refuses keys not in `allowed` (typos), naming the key and the closest allowed one.
  void checkKeys(const json& obj, const std::string& field,
                 std::initializer_list<const char*> allowed) const;

  const json& require(const json& obj, const std::string& field, const char* key) const;

  static const json* find(const json& obj, const char* key);

  /// A finite number.
  double number(const json& v, const std::string& field) const;

  /// A number stored as float: also refuses values that overflow float.
  float floatNumber(const json& v, const std::string& field) const;

  /// A number within the limit `limitField` of scene/limits.h (checked as the float or integer
  /// the scene stores), errors naming `field`.
  double limited(const json& v, const std::string& field, std::string_view limitField) const;

  bool boolean(const json& v, const std::string& field) const;

  std::string string(const json& v, const std::string& field) const;

  /// [x, y, z] in metres, each within the coordinate limit.
  glm::vec3 vec3(const json& v, const std::string& field) const;

  /// The value's type and up to 40 characters of it, for messages.
  static std::string describe(const json& v);

 private:
  std::string file_;
};

}  // namespace dpc
