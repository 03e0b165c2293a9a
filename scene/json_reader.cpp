#include "scene/json_reader.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <vector>

#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/limits.h"
#include "scene/validate.h"

namespace dpc {
namespace {

using nlohmann::json;

/// A parse error's place: e.byte is the 1-based offset of the character where parsing stopped.
[[noreturn]] void failParse(const std::string& file, const std::string& text,
                            const json::parse_error& e) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  std::string detail = e.what();
  if (auto pos = detail.find("column"); pos != std::string::npos) {
    if (auto colon = detail.find(": ", pos); colon != std::string::npos)
      detail = detail.substr(colon + 2);
  }
  throw InputError(file, "",
                   "malformed JSON at line " + std::to_string(line) + ", column " +
                       std::to_string(column) + ": " + detail);
}

/// Other parser errors, e.g. out_of_range.406 "number overflow parsing '1e999'": no offset
/// given, so the quoted literal is located in the text.
[[noreturn]] void failOther(const std::string& file, const std::string& text,
                            const json::exception& e) {
  std::string detail = e.what();
  if (auto pos = detail.find("] "); pos != std::string::npos) detail = detail.substr(pos + 2);
  std::string where;
  const size_t q0 = detail.find('\''), q1 = detail.rfind('\'');
  if (q0 != std::string::npos && q1 > q0 + 1) {
    if (size_t at = text.find(detail.substr(q0 + 1, q1 - q0 - 1)); at != std::string::npos) {
      const size_t line = size_t(std::count(text.begin(), text.begin() + long(at), '\n')) + 1;
      const size_t lineStart = text.rfind('\n', at);
      const size_t column = lineStart == std::string::npos ? at + 1 : at - lineStart;
      where = " at line " + std::to_string(line) + ", column " + std::to_string(column);
    }
  }
  throw InputError(file, "", "malformed JSON" + where + ": " + detail);
}

/// A pass over JSON text that builds nothing (nlohmann's SAX interface): it counts values,
/// refusing more than maxValues, and remembers the first key an object repeats. Parse errors
/// are thrown as the parser made them, for failParse and failOther.
class ValuesAndKeys {
 public:
  ValuesAndKeys(const std::string& file, size_t maxValues) : file_(file), max_(maxValues) {}
  bool null() { return value(); }
  bool boolean(bool) { return value(); }
  bool number_integer(json::number_integer_t) { return value(); }
  bool number_unsigned(json::number_unsigned_t) { return value(); }
  bool number_float(json::number_float_t, const json::string_t&) { return value(); }
  bool string(json::string_t&) { return value(); }
  bool binary(json::binary_t&) { return value(); }
  bool start_object(size_t) {
    open_.emplace_back();
    return value();
  }
  bool key(json::string_t& key) {
    if (!open_.back().insert(key).second && repeated_.empty()) repeated_ = key;
    return true;
  }
  bool end_object() {
    open_.pop_back();
    return true;
  }
  bool start_array(size_t) { return value(); }
  bool end_array() { return true; }
  template <class Exception>
  bool parse_error(size_t, const std::string&, const Exception& e) {
    throw e;
  }
  /// The first key an object repeats ("" if none).
  const std::string& repeated() const { return repeated_; }

 private:
  bool value() {
    if (++values_ > max_)
      throw InputError(file_, "", "JSON holds more than " + std::to_string(max_) + " values");
    return true;
  }
  const std::string& file_;
  size_t max_;
  size_t values_ = 0;
  std::vector<std::set<std::string>> open_;  // the keys of each object being read
  std::string repeated_;
};

/// Parses `text`, refusing an object that repeats a key (the parser would keep the last value
/// silently, so that the file would not say what it does) and more than maxValues values, both
/// found by a first pass that builds nothing. (The parser's own callback would do it in one
/// pass, but it rescans the enclosing array after each object: quadratic in its length.)
json parseUniqueKeys(const std::string& file, const std::string& text, size_t maxValues) {
  ValuesAndKeys check(file, maxValues);
  json::sax_parse(text, &check);
  if (!check.repeated().empty())
    throw InputError(
        file, "",
        "key \"" + check.repeated() + "\" appears twice in one object (which value is meant?)");
  return json::parse(text);
}

}  // namespace

void checkJsonDepth(const std::string& file, const std::string& text) {
  int depth = 0;
  bool inString = false;
  size_t line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (inString) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw InputError(file, "",
                         "JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                             " levels at line " + std::to_string(line));
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

std::string inQuotes(const std::string& s) {
  return "\"" + s + "\"";
}

std::string join(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string index(const std::string& parent, size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

std::filesystem::path resolve(const std::filesystem::path& folder, const std::string& p) {
  const std::filesystem::path path(p);
  return (path.is_absolute() ? path : folder / path).lexically_normal();
}

json parseJsonFile(const std::string& file, const std::string& what) {
  checkInputFile(file, kMaxSceneBytes, file, "", what);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "", "cannot open " + what);
  std::stringstream buf;
  buf << in.rdbuf();
  return parseJsonText(file, buf.str());
}

json parseJsonText(const std::string& file, const std::string& text, size_t maxValues) {
  checkJsonDepth(file, text);
  try {
    return parseUniqueKeys(file, text, maxValues);
  } catch (const json::parse_error& e) {
    failParse(file, text, e);
  } catch (const json::exception& e) {
    failOther(file, text, e);
  }
}

void JsonReader::fail(const std::string& field, const std::string& problem) const {
  throw InputError(file_, field, problem);
}

void JsonReader::expectObject(const json& v, const std::string& field) const {
  if (!v.is_object()) fail(field, "expected an object, got " + describe(v));
}

void JsonReader::checkKeys(const json& obj, const std::string& field,
                           std::initializer_list<const char*> allowed) const {
  for (const auto& item : obj.items()) {
    const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture one
    if (!key.empty() && key[0] == '_') continue;
    if (std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }))
      continue;
    std::string hint;
    size_t best = 3;
    for (const char* a : allowed) {
      const size_t d = editDistance(key, a);
      if (d < best) best = d, hint = a;
    }
    std::string allowedList;
    for (const char* a : allowed) allowedList += (allowedList.empty() ? "" : ", ") + std::string(a);
    fail(join(field, key), "unknown key " + inQuotes(key) +
                               (hint.empty() ? "" : " (did you mean " + inQuotes(hint) + "?)") +
                               "; allowed: " + allowedList);
  }
}

const json& JsonReader::require(const json& obj, const std::string& field, const char* key) const {
  auto it = obj.find(key);
  if (it == obj.end()) fail(join(field, key), "missing required key");
  return *it;
}

const json* JsonReader::find(const json& obj, const char* key) {
  auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

double JsonReader::number(const json& v, const std::string& field) const {
  if (!v.is_number()) fail(field, "expected a number, got " + describe(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(field, v.dump() + " is not a finite number");
  return x;
}

float JsonReader::floatNumber(const json& v, const std::string& field) const {
  const double x = number(v, field);
  if (std::abs(x) > double(std::numeric_limits<float>::max()))
    fail(field, v.dump() + " is too large");
  return float(x);
}

double JsonReader::limited(const json& v, const std::string& field,
                           std::string_view limitField) const {
  const Limit& limit = limitOf(limitField);
  const double written = number(v, field);
  if (limit.integer) {
    checkField(limitField, written, Origin{file_, {}}, field);
    return written;
  }
  // A float field holds the value rounded: that is what must lie within the limit; the
  // message names the value as written ("1e-300"), not only the 0 the field would hold.
  return checkFloatField(limitField, written, Origin{file_, {}}, field, v.dump());
}

bool JsonReader::boolean(const json& v, const std::string& field) const {
  if (!v.is_boolean()) fail(field, "expected true or false, got " + describe(v));
  return v.get<bool>();
}

std::string JsonReader::string(const json& v, const std::string& field) const {
  if (!v.is_string()) fail(field, "expected a string, got " + describe(v));
  // A NUL would cut a path or a name short where it reaches the C library.
  if (v.get_ref<const std::string&>().find('\0') != std::string::npos)
    fail(field, "contains a NUL character (\\u0000)");
  return v.get<std::string>();
}

glm::vec3 JsonReader::vec3(const json& v, const std::string& field) const {
  if (!v.is_array() || v.size() != 3)
    fail(field, "expected an array of 3 numbers [x, y, z] in metres, got " + describe(v));
  glm::vec3 p;
  for (int i = 0; i < 3; ++i) {
    p[i] = floatNumber(v[size_t(i)], index(field, size_t(i)));
    checkField("position", double(p[i]), Origin{file_, {}}, index(field, size_t(i)));
  }
  return p;
}

std::string JsonReader::describe(const json& v) {
  std::string text = v.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(v.type_name()) + " " + text;
}

}  // namespace dpc
