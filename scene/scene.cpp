// Scene loader: JSON (nlohmann::json) + Wavefront OBJ (tinyobjloader's callback parser).
//
// Control thread; allocates; every user mistake becomes an InputError naming the file and the
// field (dotted JSON path with [i] for array elements). The key-by-key format is
// docs/scene-format.md. Why the callback parser: tinyobjloader's LoadObj drops usemtl names it
// cannot find in a .mtl file, and we want the names alone (the .mtl may be absent). Why we
// parse "v" lines ourselves as well: tinyobjloader reads "nan", "abc" and missing coordinates
// as 0 without a word; we refuse them with the vertex number and line.
#include "scene/scene.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "common/input_error.h"
#include "common/input_file.h"

namespace dpc {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::string inQuotes(const std::string& s) {
  return "\"" + s + "\"";
}

std::string join(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string index(const std::string& parent, size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

/// Reads typed values out of the parsed JSON, throwing InputError(file, field, ...) on any
/// mismatch. Keys starting with '_' are comments and ignored everywhere.
class JsonReader {
 public:
  explicit JsonReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw InputError(file_, field, problem);
  }

  void expectObject(const json& v, const std::string& field) const {
    if (!v.is_object()) fail(field, "expected an object, got " + describe(v));
  }

  /// Refuses keys not in `allowed` (typos), naming the key and the closest allowed one.
  void checkKeys(const json& obj, const std::string& field,
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
      for (const char* a : allowed)
        allowedList += (allowedList.empty() ? "" : ", ") + std::string(a);
      fail(join(field, key), "unknown key " + inQuotes(key) +
                                 (hint.empty() ? "" : " (did you mean " + inQuotes(hint) + "?)") +
                                 "; allowed: " + allowedList);
    }
  }

  const json& require(const json& obj, const std::string& field, const char* key) const {
    auto it = obj.find(key);
    if (it == obj.end()) fail(join(field, key), "missing required key");
    return *it;
  }

  static const json* find(const json& obj, const char* key) {
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  double number(const json& v, const std::string& field) const {
    if (!v.is_number()) fail(field, "expected a number, got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(field, v.dump() + " is not a finite number");
    return x;
  }

  /// A number stored as float: also refuses values that overflow float.
  float floatNumber(const json& v, const std::string& field) const {
    const double x = number(v, field);
    if (std::abs(x) > double(std::numeric_limits<float>::max()))
      fail(field, v.dump() + " is too large");
    return float(x);
  }

  float inRange(const json& v, const std::string& field, double lo, double hi) const {
    const float x = floatNumber(v, field);
    if (x < lo || x > hi) fail(field, v.dump() + " is outside [" + fmt(lo) + ", " + fmt(hi) + "]");
    return x;
  }

  float positive(const json& v, const std::string& field) const {
    const float x = floatNumber(v, field);
    if (!(x > 0.f)) fail(field, v.dump() + " must be > 0");
    return x;
  }

  /// An integer in [lo, hi]; 4096.0 is accepted as 4096, 4096.5 is not.
  int64_t integer(const json& v, const std::string& field, int64_t lo, int64_t hi) const {
    const double x = number(v, field);
    if (x != std::floor(x)) fail(field, v.dump() + " is not an integer");
    if (x < double(lo) || x > double(hi))
      fail(field,
           v.dump() + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v.is_number_integer() ? v.get<int64_t>() : int64_t(x);
  }

  bool boolean(const json& v, const std::string& field) const {
    if (!v.is_boolean()) fail(field, "expected true or false, got " + describe(v));
    return v.get<bool>();
  }

  std::string string(const json& v, const std::string& field) const {
    if (!v.is_string()) fail(field, "expected a string, got " + describe(v));
    return v.get<std::string>();
  }

  glm::vec3 vec3(const json& v, const std::string& field) const {
    if (!v.is_array() || v.size() != 3)
      fail(field, "expected an array of 3 numbers [x, y, z] in metres, got " + describe(v));
    glm::vec3 p;
    for (int i = 0; i < 3; ++i) {
      p[i] = floatNumber(v[size_t(i)], index(field, size_t(i)));
      if (std::abs(double(p[i])) > kMaxCoordinateM)
        fail(index(field, size_t(i)), fmt(p[i]) + " m is outside [-" + fmt(kMaxCoordinateM) + ", " +
                                          fmt(kMaxCoordinateM) + "] m");
    }
    return p;
  }

  static std::string describe(const json& v) {
    std::string text = v.dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return std::string(v.type_name()) + " " + text;
  }

  static std::string fmt(double x) {
    std::ostringstream os;
    os << x;
    return os.str();
  }

 private:
  std::string file_;
};

fs::path resolve(const fs::path& folder, const std::string& p) {
  const fs::path path(p);
  return (path.is_absolute() ? path : folder / path).lexically_normal();
}

/// The JSON parser recurses once per nested array/object: bound the depth before parsing so that
/// a hostile file cannot overflow the stack.
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

json parseJson(const std::string& file) {
  checkInputFile(file, kMaxSceneBytes, file, "", "scene file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "", "cannot open scene file");
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string text = buf.str();
  checkJsonDepth(file, text);
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the character where parsing stopped.
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
  } catch (const json::exception& e) {
    // E.g. out_of_range.406 "number overflow parsing '1e999'": no offset given, so locate the
    // quoted literal in the text.
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
}

// ---------------------------------------------------------------------------------------------
// Materials

/// A per-band coefficient: a number in [0, 1] for every octave band, or an array of exactly
/// kNumBands numbers in [0, 1] (63 Hz .. 8 kHz). Errors name `field` (and the element).
Bands readBandsInUnitRange(const JsonReader& r, const json& a, const std::string& field) {
  Bands out;
  if (a.is_array()) {
    if (a.size() != size_t(kNumBands))
      r.fail(field, "expected " + std::to_string(kNumBands) +
                        " values (octave bands 63 Hz .. 8 kHz), got " + std::to_string(a.size()));
    for (int b = 0; b < kNumBands; ++b)
      out[b] = r.inRange(a[size_t(b)], index(field, size_t(b)), 0.0, 1.0);
  } else if (a.is_number()) {
    out = Bands(r.inRange(a, field, 0.0, 1.0));
  } else {
    r.fail(field, "expected a number or an array of " + std::to_string(kNumBands) +
                      " numbers in [0, 1], got " + JsonReader::describe(a));
  }
  return out;
}

Material readMaterial(const JsonReader& r, const json& v, const std::string& name,
                      const std::string& field) {
  r.expectObject(v, field);
  r.checkKeys(v, field, {"absorption", "scattering", "source"});
  Material m;
  m.name = name;
  m.absorption =
      readBandsInUnitRange(r, r.require(v, field, "absorption"), join(field, "absorption"));
  if (const json* s = JsonReader::find(v, "scattering"))
    m.scattering = readBandsInUnitRange(r, *s, join(field, "scattering"));
  if (const json* s = JsonReader::find(v, "source")) r.string(*s, join(field, "source"));
  return m;
}

// ---------------------------------------------------------------------------------------------
// OBJ

struct ObjFace {
  std::vector<int> vertexIndex;  // raw OBJ indices (1-based, or negative = relative)
  int verticesSoFar = 0;         // for resolving negative indices
  int materialSlot = -1;         // index into ObjData::materialNames, -1 = no usemtl
};

struct ObjData {
  std::vector<glm::vec3> vertices;
  std::vector<ObjFace> faces;
  std::vector<std::string> materialNames;
  int currentMaterial = -1;
  int callbackVertices = 0;
};

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

/// Parses the "v x y z [w]" lines ourselves (strtod: sees nan/inf, refuses garbage).
void readObjVertices(const std::string& objFile, const std::string& text, ObjData& obj) {
  std::istringstream in(text);
  std::string line;
  size_t lineNo = 0, faceNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    const char* p = line.c_str();
    p += std::strspn(p, " \t");
    if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) {
      // tinyobjloader parses indices into int: refuse what would wrap before it does.
      ++faceNo;
      for (p += 2; *p != '\0';) {
        p += std::strspn(p, " \t\r/");
        char* end = nullptr;
        const long long raw = std::strtoll(p, &end, 10);
        if (end == p) {
          p += std::strcspn(p, " \t\r/");
          continue;
        }
        if (raw > std::numeric_limits<int>::max() || raw < -std::numeric_limits<int>::max())
          throw InputError(
              objFile, "face " + std::to_string(faceNo) + " (line " + std::to_string(lineNo) + ")",
              "vertex index " + std::string(p, size_t(end - p)) + " is out of range");
        p = end;
      }
      continue;
    }
    if (p[0] != 'v' || (p[1] != ' ' && p[1] != '\t')) continue;
    p += 2;
    const size_t vertexNo = obj.vertices.size() + 1;
    const std::string field =
        "vertex " + std::to_string(vertexNo) + " (line " + std::to_string(lineNo) + ")";
    glm::vec3 v{0.f};
    for (int i = 0; i < 3; ++i) {
      p += std::strspn(p, " \t\r");
      if (*p == '\0') throw InputError(objFile, field, "expected 3 coordinates x y z");
      char* end = nullptr;
      errno = 0;
      const double x = std::strtod(p, &end);
      if (end == p) {
        const size_t n = std::strcspn(p, " \t\r");
        throw InputError(objFile, field, inQuotes(std::string(p, n)) + " is not a number");
      }
      if (!std::isfinite(x) || std::abs(x) > double(std::numeric_limits<float>::max()))
        throw InputError(objFile, field,
                         "coordinate " + std::string(p, size_t(end - p)) + " is not finite");
      if (std::abs(x) > kMaxCoordinateM)
        throw InputError(objFile, field,
                         "coordinate " + std::string(p, size_t(end - p)) + " m is outside +-" +
                             std::to_string(int64_t(kMaxCoordinateM)) + " m");
      v[i] = float(x);
      p = end;
    }
    obj.vertices.push_back(v);
  }
}

/// meshField: the scene key naming the file ("mesh", "objects[2].mesh"), for errors.
ObjData readObj(const std::string& sceneFile, const std::string& objFile,
                const std::string& meshField) {
  checkInputFile(objFile, kMaxMeshBytes, sceneFile, meshField, "mesh file");
  std::ifstream in(objFile, std::ios::binary);
  if (!in) throw InputError(sceneFile, meshField, "cannot open mesh file " + inQuotes(objFile));
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string text = buf.str();

  ObjData obj;
  readObjVertices(objFile, text, obj);

  tinyobj::callback_t cb;
  cb.vertex_cb = [](void* user, tinyobj::real_t, tinyobj::real_t, tinyobj::real_t,
                    tinyobj::real_t) { ++static_cast<ObjData*>(user)->callbackVertices; };
  cb.index_cb = [](void* user, tinyobj::index_t* indices, int n) {
    auto& o = *static_cast<ObjData*>(user);
    ObjFace f;
    for (int i = 0; i < n; ++i) f.vertexIndex.push_back(indices[i].vertex_index);
    f.verticesSoFar = o.callbackVertices;
    f.materialSlot = o.currentMaterial;
    o.faces.push_back(std::move(f));
  };
  cb.usemtl_cb = [](void* user, const char* name, int) {
    auto& o = *static_cast<ObjData*>(user);
    const std::string n = trim(name);
    auto it = std::find(o.materialNames.begin(), o.materialNames.end(), n);
    if (it == o.materialNames.end()) {
      o.materialNames.push_back(n);
      o.currentMaterial = int(o.materialNames.size()) - 1;
    } else {
      o.currentMaterial = int(it - o.materialNames.begin());
    }
  };
  std::istringstream stream(text);
  std::string warn, err;
  if (!tinyobj::LoadObjWithCallback(stream, cb, &obj, nullptr, &warn, &err))
    throw InputError(objFile, "", "cannot parse OBJ: " + trim(err));
  if (obj.callbackVertices != int(obj.vertices.size()))
    throw InputError(objFile, "",
                     "vertex count mismatch (" + std::to_string(obj.vertices.size()) + " vs " +
                         std::to_string(obj.callbackVertices) + "); unsupported 'v' syntax?");
  return obj;
}

/// Builds the triangle mesh: resolves indices, fan-triangulates polygons (convex assumed),
/// maps usemtl names to materials, drops degenerate triangles with a warning.
void buildMesh(const std::string& sceneFile, const std::string& objFile, const ObjData& obj,
               const std::vector<Material>& materials, Mesh& mesh,
               std::vector<std::string>& warnings) {
  auto materialIndex = [&](const std::string& name) -> int {
    for (size_t i = 0; i < materials.size(); ++i)
      if (materials[i].name == name) return int(i);
    return -1;
  };
  std::vector<int> slotToMaterial;
  for (const std::string& name : obj.materialNames) {
    const int m = materialIndex(name);
    if (m < 0)
      throw InputError(objFile, "usemtl " + name,
                       "material " + inQuotes(name) + " is not defined in " + sceneFile +
                           " (materials." + name + ")");
    slotToMaterial.push_back(m);
  }
  if (obj.faces.empty()) throw InputError(objFile, "", "mesh is empty (no faces)");

  const int nv = int(obj.vertices.size());
  mesh.vertices = obj.vertices;
  size_t degenerate = 0, candidates = 0, firstDegenerateFace = 0;
  for (size_t fi = 0; fi < obj.faces.size(); ++fi) {
    const ObjFace& f = obj.faces[fi];
    const std::string field = "face " + std::to_string(fi + 1);
    if (f.vertexIndex.size() < 3)
      throw InputError(objFile, field, "a face needs at least 3 vertices");
    std::vector<uint32_t> idx;
    for (int raw : f.vertexIndex) {
      int i = raw > 0 ? raw - 1 : (raw < 0 ? f.verticesSoFar + raw : -1);
      if (raw == 0 || i < 0 || i >= nv)
        throw InputError(objFile, field,
                         "vertex index " + std::to_string(raw) + " is out of range (" +
                             std::to_string(nv) + " vertices)");
      idx.push_back(uint32_t(i));
    }
    int material = -1;
    if (f.materialSlot >= 0) {
      material = slotToMaterial[size_t(f.materialSlot)];
    } else {
      material = materialIndex("default");
      if (material < 0)
        throw InputError(
            objFile, field,
            "face has no usemtl and " + sceneFile + " defines no material named \"default\"");
    }
    for (size_t k = 1; k + 1 < idx.size(); ++k) {
      const std::array<uint32_t, 3> tri{idx[0], idx[k], idx[k + 1]};
      ++candidates;
      const glm::vec3 a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]],
                      c = mesh.vertices[tri[2]];
      const glm::vec3 e0 = b - a, e1 = c - a, e2 = c - b;
      const glm::vec3 n = glm::vec3(e0.y * e1.z - e0.z * e1.y, e0.z * e1.x - e0.x * e1.z,
                                    e0.x * e1.y - e0.y * e1.x);
      const double twiceArea = std::sqrt(double(n.x) * n.x + double(n.y) * n.y + double(n.z) * n.z);
      auto len2 = [](glm::vec3 e) {
        return double(e.x) * e.x + double(e.y) * e.y + double(e.z) * e.z;
      };
      const double longest2 = std::max({len2(e0), len2(e1), len2(e2)});
      // Zero area, or a sliver whose height is below 1e-6 of its longest edge.
      if (!(twiceArea > 1e-6 * longest2)) {
        if (degenerate++ == 0) firstDegenerateFace = fi + 1;
        continue;
      }
      mesh.triangles.push_back(tri);
      mesh.materialIndex.push_back(uint32_t(material));
    }
  }
  if (mesh.triangles.empty())
    throw InputError(objFile, "",
                     "all " + std::to_string(candidates) +
                         " triangles are degenerate (zero area); nothing to trace");
  if (degenerate > 0)
    warnings.push_back(objFile + ": " + std::to_string(degenerate) +
                       " degenerate (zero-area) triangle(s) dropped, the first from face " +
                       std::to_string(firstDegenerateFace));
}

/// Reads a keyframe time at kf + ".t": finite, >= 0, greater than `previous` (if any).
double keyTime(const JsonReader& r, const json& k, const std::string& kf,
               const std::optional<double>& previous) {
  const double t = r.number(r.require(k, kf, "t"), join(kf, "t"));
  if (t < 0.0) r.fail(join(kf, "t"), k["t"].dump() + " must be >= 0");
  if (previous && !(t > *previous))
    r.fail(join(kf, "t"), k["t"].dump() + " is not greater than the previous keyframe's t (" +
                              JsonReader::fmt(*previous) + "); times must be strictly increasing");
  return t;
}

/// Position-only keyframes {t, position} (sources).
std::vector<Keyframe> readPositionKeys(const JsonReader& r, const json& t, const std::string& tf) {
  if (!t.is_array() || t.empty())
    r.fail(tf, "expected a non-empty array of {\"t\", \"position\"} keyframes, got " +
                   JsonReader::describe(t));
  std::vector<Keyframe> keys;
  for (size_t i = 0; i < t.size(); ++i) {
    const std::string kf = index(tf, i);
    const json& k = t[i];
    r.expectObject(k, kf);
    r.checkKeys(k, kf, {"t", "position"});
    Keyframe key;
    key.timeSeconds =
        keyTime(r, k, kf, keys.empty() ? std::nullopt : std::optional(keys.back().timeSeconds));
    key.position = r.vec3(r.require(k, kf, "position"), join(kf, "position"));
    keys.push_back(key);
  }
  return keys;
}

/// [x, y, z, w] (glTF order) of non-zero length, normalised.
glm::quat readQuaternion(const JsonReader& r, const json& v, const std::string& field) {
  if (!v.is_array() || v.size() != 4)
    r.fail(field, "expected a unit quaternion [x, y, z, w], got " + JsonReader::describe(v));
  float c[4];
  for (int i = 0; i < 4; ++i) c[i] = r.floatNumber(v[size_t(i)], index(field, size_t(i)));
  const double n = std::sqrt(double(c[0]) * c[0] + double(c[1]) * c[1] + double(c[2]) * c[2] +
                             double(c[3]) * c[3]);
  if (!(n > 1e-6)) r.fail(field, v.dump() + " has zero length; a rotation needs a unit quaternion");
  // Not exactly unit (rounded decimals in a file): normalised rather than refused.
  return glm::quat(float(c[3] / n), float(c[0] / n), float(c[1] / n), float(c[2] / n));
}

void readObjects(const JsonReader& r, const json& v, const fs::path& folder, SceneDesc& scene) {
  const std::string field = "objects";
  if (!v.is_array()) r.fail(field, "expected an array of objects, got " + JsonReader::describe(v));
  if (v.size() > kMaxObjects)
    r.fail(field, std::to_string(v.size()) + " objects, more than the limit of " +
                      std::to_string(kMaxObjects));
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string f = index(field, i);
    const json& o = v[i];
    r.expectObject(o, f);
    r.checkKeys(o, f, {"name", "mesh", "trajectory", "loop"});
    ObjectDesc obj;
    obj.name = r.string(r.require(o, f, "name"), join(f, "name"));
    if (obj.name.empty()) r.fail(join(f, "name"), "must not be empty");
    for (const ObjectDesc& other : scene.objects)
      if (other.name == obj.name)
        r.fail(join(f, "name"), "duplicate object name " + inQuotes(obj.name));
    obj.meshPath = resolve(folder, r.string(r.require(o, f, "mesh"), join(f, "mesh"))).string();
    const std::string tf = join(f, "trajectory");
    const json& t = r.require(o, f, "trajectory");
    if (!t.is_array() || t.empty())
      r.fail(tf,
             "expected a non-empty array of {\"t\", \"position\", \"rotation\"?} "
             "keyframes, got " +
                 JsonReader::describe(t));
    for (size_t k = 0; k < t.size(); ++k) {
      const std::string kf = index(tf, k);
      const json& kv = t[k];
      r.expectObject(kv, kf);
      r.checkKeys(kv, kf, {"t", "position", "rotation"});
      ObjectKeyframe key;
      key.timeSeconds = keyTime(
          r, kv, kf,
          obj.trajectory.empty() ? std::nullopt : std::optional(obj.trajectory.back().timeSeconds));
      key.position = r.vec3(r.require(kv, kf, "position"), join(kf, "position"));
      if (const json* q = JsonReader::find(kv, "rotation"))
        key.rotation = readQuaternion(r, *q, join(kf, "rotation"));
      obj.trajectory.push_back(key);
    }
    if (const json* l = JsonReader::find(o, "loop")) obj.loop = r.boolean(*l, join(f, "loop"));
    scene.objects.push_back(std::move(obj));
  }
}

// ---------------------------------------------------------------------------------------------
// Sections

void readSources(const JsonReader& r, const json& v, const fs::path& folder, SceneDesc& scene) {
  const std::string field = "sources";
  if (!v.is_array()) r.fail(field, "expected an array of sources, got " + JsonReader::describe(v));
  if (v.empty()) r.fail(field, "at least one source is required");
  if (v.size() > kMaxSources)
    r.fail(field, std::to_string(v.size()) + " sources, more than the limit of " +
                      std::to_string(kMaxSources));
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string f = index(field, i);
    const json& s = v[i];
    r.expectObject(s, f);
    r.checkKeys(s, f,
                {"name", "position", "signal", "gain_db", "loop", "trajectory", "trajectory_loop"});
    SourceDesc src;
    src.name = r.string(r.require(s, f, "name"), join(f, "name"));
    if (src.name.empty()) r.fail(join(f, "name"), "must not be empty");
    for (const SourceDesc& other : scene.sources)
      if (other.name == src.name)
        r.fail(join(f, "name"), "duplicate source name " + inQuotes(src.name));
    if (const json* t = JsonReader::find(s, "trajectory"))
      src.trajectory = readPositionKeys(r, *t, join(f, "trajectory"));
    if (const json* p = JsonReader::find(s, "position"))
      src.position = r.vec3(*p, join(f, "position"));
    else if (!src.trajectory.empty())
      src.position = src.trajectory.front().position;
    else
      r.fail(join(f, "position"), "missing required key (needed when there is no trajectory)");
    if (const json* l = JsonReader::find(s, "trajectory_loop"))
      src.trajectoryLoop = r.boolean(*l, join(f, "trajectory_loop"));
    // No signal: the source's dry input comes from a host (C API, plugin) or is silent.
    if (const json* sig = JsonReader::find(s, "signal")) {
      const std::string signal = r.string(*sig, join(f, "signal"));
      const fs::path resolved = resolve(folder, signal);
      std::error_code ec;
      if (!fs::is_regular_file(resolved, ec))
        r.fail(join(f, "signal"), "file " + inQuotes(resolved.string()) + " not found");
      src.signalPath = resolved.string();
    }
    if (const json* g = JsonReader::find(s, "gain_db"))
      src.gainDb = r.inRange(*g, join(f, "gain_db"), -200.0, 200.0);
    if (const json* l = JsonReader::find(s, "loop")) src.loop = r.boolean(*l, join(f, "loop"));
    scene.sources.push_back(src);
  }
}

void readListener(const JsonReader& r, const json& v, const std::string& field, bool named,
                  ListenerDesc& listener) {
  r.expectObject(v, field);
  if (named) {
    r.checkKeys(v, field, {"name", "position", "radius", "trajectory", "loop", "yaw", "pitch"});
    listener.name = r.string(r.require(v, field, "name"), join(field, "name"));
    if (listener.name.empty()) r.fail(join(field, "name"), "must not be empty");
  } else {
    r.checkKeys(v, field, {"position", "radius", "trajectory", "loop", "yaw", "pitch"});
  }
  if (const json* t = JsonReader::find(v, "trajectory")) {
    const std::string tf = join(field, "trajectory");
    if (!t->is_array())
      r.fail(tf, "expected an array of {\"t\", \"position\"} keyframes, got " +
                     JsonReader::describe(*t));
    for (size_t i = 0; i < t->size(); ++i) {
      const std::string kf = index(tf, i);
      const json& k = (*t)[i];
      r.expectObject(k, kf);
      r.checkKeys(k, kf, {"t", "position", "yaw", "pitch"});
      Keyframe key;
      key.timeSeconds = r.number(r.require(k, kf, "t"), join(kf, "t"));
      if (key.timeSeconds < 0.0) r.fail(join(kf, "t"), k["t"].dump() + " must be >= 0");
      if (!listener.trajectory.empty() &&
          !(key.timeSeconds > listener.trajectory.back().timeSeconds))
        r.fail(join(kf, "t"), k["t"].dump() + " is not greater than the previous keyframe's t (" +
                                  JsonReader::fmt(listener.trajectory.back().timeSeconds) +
                                  "); times must be strictly increasing");
      key.position = r.vec3(r.require(k, kf, "position"), join(kf, "position"));
      if (const json* y = JsonReader::find(k, "yaw"))
        key.yawDegrees = float(r.inRange(*y, join(kf, "yaw"), -3600.0, 3600.0));
      if (const json* p = JsonReader::find(k, "pitch"))
        key.pitchDegrees = float(r.inRange(*p, join(kf, "pitch"), -90.0, 90.0));
      if (!listener.trajectory.empty() &&
          listener.trajectory.front().yawDegrees.has_value() != key.yawDegrees.has_value())
        r.fail(join(kf, "yaw"), "give \"yaw\" on every keyframe or on none");
      listener.trajectory.push_back(key);
    }
  }
  if (const json* p = JsonReader::find(v, "position")) {
    listener.position = r.vec3(*p, join(field, "position"));
  } else if (!listener.trajectory.empty()) {
    listener.position = listener.trajectory.front().position;
  } else {
    r.fail(join(field, "position"), "missing required key (needed when there is no trajectory)");
  }
  if (const json* rad = JsonReader::find(v, "radius"))
    listener.radius = r.positive(*rad, join(field, "radius"));
  if (const json* l = JsonReader::find(v, "loop"))
    listener.loop = r.boolean(*l, join(field, "loop"));
  if (const json* y = JsonReader::find(v, "yaw"))
    listener.yawDegrees = float(r.inRange(*y, join(field, "yaw"), -3600.0, 3600.0));
  if (const json* p = JsonReader::find(v, "pitch"))
    listener.pitchDegrees = float(r.inRange(*p, join(field, "pitch"), -90.0, 90.0));
}

void readPropagation(const JsonReader& r, const json& v, PropagationSettings& p) {
  const std::string field = "propagation";
  r.expectObject(v, field);
  r.checkKeys(v, field,
              {"rays_per_frame", "max_order", "patch_size", "cache_tau", "cache_memory_mb",
               "frame_rate", "ir_length", "seed", "estimator", "dpc_weighting", "speed_of_sound",
               "temperature", "humidity", "air_absorption", "diffraction", "roulette_threshold_db"});
  auto f = [&](const char* key) { return join(field, key); };
  if (const json* x = JsonReader::find(v, "rays_per_frame"))
    p.raysPerFrame = int(r.integer(*x, f("rays_per_frame"), 1, 100'000'000));
  if (const json* x = JsonReader::find(v, "max_order"))
    p.maxOrder = int(r.integer(*x, f("max_order"), 0, 10'000));
  if (const json* x = JsonReader::find(v, "patch_size"))
    p.patchSize = r.positive(*x, f("patch_size"));
  if (const json* x = JsonReader::find(v, "cache_tau")) {
    p.cacheTau = r.floatNumber(*x, f("cache_tau"));
    if (p.cacheTau < 0.f) r.fail(f("cache_tau"), x->dump() + " must be >= 0");
  }
  if (const json* x = JsonReader::find(v, "cache_memory_mb")) {
    p.cacheMemoryMb = r.positive(*x, f("cache_memory_mb"));
    if (p.cacheMemoryMb > 16384.f)
      r.fail(f("cache_memory_mb"), x->dump() + " is outside (0, 16384] MB");
  }
  if (const json* x = JsonReader::find(v, "frame_rate")) {
    p.frameRate = r.positive(*x, f("frame_rate"));
    if (p.frameRate < 1.f || p.frameRate > 120.f)
      r.fail(f("frame_rate"), x->dump() + " is outside [1, 120] Hz");
  }
  if (const json* x = JsonReader::find(v, "ir_length")) {
    p.irLength = r.positive(*x, f("ir_length"));
    if (p.irLength > 60.f) r.fail(f("ir_length"), x->dump() + " is outside (0, 60]");
  }
  if (const json* x = JsonReader::find(v, "seed")) {
    if (!x->is_number_unsigned() && !(x->is_number_integer() && x->get<int64_t>() >= 0))
      r.fail(f("seed"), "expected an unsigned integer, got " + JsonReader::describe(*x));
    p.seed = x->get<uint64_t>();
  }
  if (const json* x = JsonReader::find(v, "estimator")) {
    const std::string s = r.string(*x, f("estimator"));
    const auto e = parseEstimator(s);
    if (!e) r.fail(f("estimator"), inQuotes(s) + " is not one of \"dpc\", \"path_tracing\"");
    p.estimator = *e;
  }
  if (const json* x = JsonReader::find(v, "dpc_weighting")) {
    const std::string s = r.string(*x, f("dpc_weighting"));
    const auto w = parseDpcWeighting(s);
    if (!w)
      r.fail(f("dpc_weighting"), inQuotes(s) + " is not one of \"ema\", \"seed\", \"window\"");
    p.dpcWeighting = *w;
  }
  if (const json* x = JsonReader::find(v, "temperature"))
    p.temperatureC = r.inRange(*x, f("temperature"), -50.0, 60.0);
  if (const json* x = JsonReader::find(v, "humidity"))
    p.humidityPercent = r.inRange(*x, f("humidity"), 0.0, 100.0);
  if (const json* x = JsonReader::find(v, "speed_of_sound")) {
    p.speedOfSound = r.inRange(*x, f("speed_of_sound"), 1.0, 10000.0);
  } else {
    // Ideal-gas dry air: c = 331.3 sqrt(1 + T / 273.15) m/s.
    p.speedOfSound = float(331.3 * std::sqrt(1.0 + double(p.temperatureC) / 273.15));
  }
  if (const json* x = JsonReader::find(v, "air_absorption"))
    p.airAbsorption = r.boolean(*x, f("air_absorption"));
  if (const json* x = JsonReader::find(v, "diffraction"))
    p.diffraction = r.boolean(*x, f("diffraction"));
  if (const json* x = JsonReader::find(v, "roulette_threshold_db")) {
    const double db = r.inRange(*x, f("roulette_threshold_db"), -300.0, 0.0);
    p.rouletteThreshold = float(std::pow(10.0, db / 10.0));
  }
}

void readAudio(const JsonReader& r, const json& v, const fs::path& folder, AudioSettings& a) {
  const std::string field = "audio";
  r.expectObject(v, field);
  r.checkKeys(v, field, {"sample_rate", "block_size", "output", "hrtf"});
  if (const json* x = JsonReader::find(v, "output")) {
    const std::string s = r.string(*x, join(field, "output"));
    const auto o = parseOutputFormat(s);
    if (!o)
      r.fail(join(field, "output"),
             inQuotes(s) + " is not one of \"mono\", \"stereo\", \"binaural\"");
    a.output = *o;
  }
  if (const json* x = JsonReader::find(v, "hrtf")) {
    const fs::path resolved = resolve(folder, r.string(*x, join(field, "hrtf")));
    std::error_code ec;
    if (!fs::is_regular_file(resolved, ec))
      r.fail(join(field, "hrtf"), "file " + inQuotes(resolved.string()) + " not found");
    a.hrtfPath = resolved.string();
  }
  if (const json* x = JsonReader::find(v, "sample_rate"))
    a.sampleRate = int(r.integer(*x, join(field, "sample_rate"), 16000, 192000));
  if (const json* x = JsonReader::find(v, "block_size"))
    a.blockSize = int(r.integer(*x, join(field, "block_size"), 16, 8192));
}

}  // namespace

std::vector<uint32_t> weldedVertexIds(const Mesh& mesh) {
  struct Key {
    uint32_t x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    size_t operator()(const Key& k) const {
      return size_t(k.x) * 0x9e3779b97f4a7c15ULL ^ size_t(k.y) * 0xc2b2ae3d27d4eb4fULL ^
             size_t(k.z) * 0x165667b19e3779f9ULL;
    }
  };
  auto bits = [](float f) {
    f += 0.f;  // -0 and +0 are one position
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
  };
  std::unordered_map<Key, uint32_t, Hash> first;
  first.reserve(mesh.vertices.size());
  std::vector<uint32_t> ids(mesh.vertices.size());
  for (uint32_t i = 0; i < mesh.vertices.size(); ++i) {
    const glm::vec3& v = mesh.vertices[i];
    ids[i] = first.try_emplace(Key{bits(v.x), bits(v.y), bits(v.z)}, i).first->second;
  }
  return ids;
}

SceneDesc loadScene(const std::string& path) {
  SceneDesc scene;
  scene.path = path;
  scene.propagation.speedOfSound =
      float(331.3 * std::sqrt(1.0 + double(scene.propagation.temperatureC) / 273.15));
  const json root = parseJson(path);
  const JsonReader r(path);
  if (!root.is_object())
    r.fail("", "expected a JSON object at the top level, got " + JsonReader::describe(root));
  r.checkKeys(
      root, "",
      {"mesh", "materials", "sources", "listener", "listeners", "objects", "propagation", "audio"});
  const fs::path folder = fs::path(path).parent_path();

  // Materials (sorted by name: nlohmann::json objects iterate in key order).
  const json& mats = r.require(root, "", "materials");
  r.expectObject(mats, "materials");
  for (const auto& [name, value] : mats.items()) {
    if (!name.empty() && name[0] == '_') continue;
    if (name.empty()) r.fail("materials", "a material name must not be empty");
    scene.materials.push_back(readMaterial(r, value, name, "materials." + name));
  }
  if (scene.materials.empty()) r.fail("materials", "at least one material is required");

  readSources(r, r.require(root, "", "sources"), folder, scene);
  const json* one = JsonReader::find(root, "listener");
  const json* many = JsonReader::find(root, "listeners");
  if (one && many) r.fail("listeners", "give either \"listener\" or \"listeners\", not both");
  if (one) {
    scene.listeners.emplace_back();
    readListener(r, *one, "listener", false, scene.listeners.back());
  } else if (many) {
    if (!many->is_array() || many->empty())
      r.fail("listeners",
             "expected a non-empty array of listeners, got " + JsonReader::describe(*many));
    if (many->size() > kMaxListeners)
      r.fail("listeners", std::to_string(many->size()) + " listeners, more than the limit of " +
                              std::to_string(kMaxListeners));
    for (size_t i = 0; i < many->size(); ++i) {
      ListenerDesc l;
      readListener(r, (*many)[i], index("listeners", i), true, l);
      for (const ListenerDesc& other : scene.listeners)
        if (other.name == l.name)
          r.fail(index("listeners", i) + ".name", "duplicate listener name " + inQuotes(l.name));
      scene.listeners.push_back(std::move(l));
    }
  } else {
    r.fail("listener", "missing required key (or give \"listeners\")");
  }
  if (const json* o = JsonReader::find(root, "objects")) readObjects(r, *o, folder, scene);
  if (const json* p = JsonReader::find(root, "propagation"))
    readPropagation(r, *p, scene.propagation);
  if (const json* a = JsonReader::find(root, "audio")) readAudio(r, *a, folder, scene.audio);

  // Mesh last: the most expensive step, after the cheap checks.
  const std::string meshName = r.string(r.require(root, "", "mesh"), "mesh");
  scene.meshPath = resolve(folder, meshName).string();
  const ObjData obj = readObj(path, scene.meshPath, "mesh");
  buildMesh(path, scene.meshPath, obj, scene.materials, scene.mesh, scene.warnings);
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    ObjectDesc& o = scene.objects[i];
    const ObjData od = readObj(path, o.meshPath, index("objects", i) + ".mesh");
    buildMesh(path, o.meshPath, od, scene.materials, o.mesh, scene.warnings);
  }
  std::vector<bool> used(scene.materials.size(), false);
  for (uint32_t m : scene.mesh.materialIndex) used[m] = true;
  for (const ObjectDesc& o : scene.objects)
    for (uint32_t m : o.mesh.materialIndex) used[m] = true;
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (!used[i])
      scene.warnings.push_back(path + ": materials." + scene.materials[i].name +
                               ": not used by any triangle of " + scene.meshPath +
                               (scene.objects.empty() ? "" : " or of an object"));
  return scene;
}

namespace {

/// Position along keyframes (linear; clamped, or wrapped when loop is set).
glm::vec3 positionAlong(const std::vector<Keyframe>& k, bool loop, const glm::vec3& fixed,
                        double t) {
  if (k.empty()) return fixed;
  if (k.size() == 1 || !std::isfinite(t)) return k.front().position;
  const double t0 = k.front().timeSeconds, t1 = k.back().timeSeconds;
  if (loop) {
    const double period = t1 - t0;
    t = t0 + (t - t0) - period * std::floor((t - t0) / period);  // into [t0, t1)
  }
  if (t <= t0) return k.front().position;
  if (t >= t1) return k.back().position;
  // First keyframe with time > t; t lies in [prev.time, next.time).
  const auto next = std::upper_bound(
      k.begin(), k.end(), t, [](double x, const Keyframe& key) { return x < key.timeSeconds; });
  const auto prev = next - 1;
  const double u = (t - prev->timeSeconds) / (next->timeSeconds - prev->timeSeconds);
  return prev->position + float(u) * (next->position - prev->position);
}

}  // namespace

glm::vec3 listenerPositionAt(const ListenerDesc& listener, double t) {
  return positionAlong(listener.trajectory, listener.loop, listener.position, t);
}

glm::vec3 sourcePositionAt(const SourceDesc& source, double t) {
  return positionAlong(source.trajectory, source.trajectoryLoop, source.position, t);
}

Pose objectPoseAt(const ObjectDesc& object, double t) {
  const auto& k = object.trajectory;
  if (k.empty()) return {};
  if (k.size() == 1 || !std::isfinite(t)) return {k.front().position, k.front().rotation};
  const double t0 = k.front().timeSeconds, t1 = k.back().timeSeconds;
  if (object.loop) t = t0 + (t - t0) - (t1 - t0) * std::floor((t - t0) / (t1 - t0));
  if (t <= t0) return {k.front().position, k.front().rotation};
  if (t >= t1) return {k.back().position, k.back().rotation};
  const auto next =
      std::upper_bound(k.begin(), k.end(), t,
                       [](double x, const ObjectKeyframe& key) { return x < key.timeSeconds; });
  const auto prev = next - 1;
  const float u = float((t - prev->timeSeconds) / (next->timeSeconds - prev->timeSeconds));
  Pose p;
  p.position = prev->position + u * (next->position - prev->position);
  // Shorter arc: q and -q are the same rotation.
  glm::quat b = next->rotation;
  if (glm::dot(prev->rotation, b) < 0.f) b = -b;
  p.rotation = glm::normalize(glm::slerp(prev->rotation, b, u));
  return p;
}

void evaluateWorld(const SceneDesc& scene, double t, WorldState& state) {
  state.timeSeconds = t;
  state.listenerPositions.resize(scene.listeners.size());
  state.listenerOrientations.resize(scene.listeners.size());
  for (size_t i = 0; i < scene.listeners.size(); ++i) {
    state.listenerPositions[i] = listenerPositionAt(scene.listeners[i], t);
    state.listenerOrientations[i] = listenerOrientationAt(scene.listeners[i], t);
  }
  state.sourcePositions.resize(scene.sources.size());
  for (size_t i = 0; i < scene.sources.size(); ++i)
    state.sourcePositions[i] = sourcePositionAt(scene.sources[i], t);
  state.objectPoses.resize(scene.objects.size());
  for (size_t i = 0; i < scene.objects.size(); ++i)
    state.objectPoses[i] = objectPoseAt(scene.objects[i], t);
}

size_t listenerIndex(const SceneDesc& scene, const std::string& name, const std::string& flag) {
  std::string known;
  for (size_t i = 0; i < scene.listeners.size(); ++i) {
    if (scene.listeners[i].name == name) return i;
    known += (known.empty() ? "" : ", ") + inQuotes(scene.listeners[i].name);
  }
  throw InputError(
      "command line", flag,
      "no listener named " + inQuotes(name) + " in " + scene.path + " (listeners: " + known + ")");
}

glm::vec3 Orientation::forward() const {
  const float cp = std::cos(pitchRadians);
  return {cp * std::cos(yawRadians), std::sin(pitchRadians), -cp * std::sin(yawRadians)};
}

glm::vec3 Orientation::up() const {
  const float sp = std::sin(pitchRadians);
  return {-sp * std::cos(yawRadians), std::cos(pitchRadians), sp * std::sin(yawRadians)};
}

Orientation listenerOrientationAt(const ListenerDesc& listener, double t) {
  constexpr float kDeg = float(3.14159265358979323846 / 180.0);
  Orientation o;
  o.yawRadians = listener.yawDegrees * kDeg;
  o.pitchRadians = listener.pitchDegrees * kDeg;
  const auto& k = listener.trajectory;
  if (k.empty()) return o;
  if (listener.loop && k.size() > 1) {
    const double t0 = k.front().timeSeconds, period = k.back().timeSeconds - t0;
    t = t0 + (t - t0) - period * std::floor((t - t0) / period);
  }
  // Segment [i, i+1] holding t (clamped to the ends).
  size_t i = 0;
  while (i + 2 < k.size() && t >= k[i + 1].timeSeconds) ++i;
  if (k.front().yawDegrees) {
    if (k.size() == 1 || t <= k.front().timeSeconds) {
      o.yawRadians = *k.front().yawDegrees * kDeg;
      o.pitchRadians = k.front().pitchDegrees.value_or(0.f) * kDeg;
      return o;
    }
    const Keyframe &a = k[i], &b = k[i + 1];
    const double u = std::clamp((t - a.timeSeconds) / (b.timeSeconds - a.timeSeconds), 0.0, 1.0);
    float dy = std::remainder(*b.yawDegrees - *a.yawDegrees, 360.f);  // shorter arc
    o.yawRadians = (*a.yawDegrees + float(u) * dy) * kDeg;
    o.pitchRadians = (a.pitchDegrees.value_or(0.f) +
                      float(u) * (b.pitchDegrees.value_or(0.f) - a.pitchDegrees.value_or(0.f))) *
                     kDeg;
    return o;
  }
  // Face the walking direction: this segment's, or the last moving segment's before it.
  for (size_t j = i + 1; j-- > 0;) {
    if (j + 1 >= k.size()) continue;
    const glm::vec3 v = k[j + 1].position - k[j].position;
    if (v.x * v.x + v.z * v.z > 1e-12f) {
      o.yawRadians = std::atan2(-v.z, v.x);
      return o;
    }
  }
  return o;
}

std::optional<OutputFormat> parseOutputFormat(const std::string& s) {
  if (s == "mono") return OutputFormat::kMono;
  if (s == "stereo") return OutputFormat::kStereo;
  if (s == "binaural") return OutputFormat::kBinaural;
  return std::nullopt;
}

std::optional<Estimator> parseEstimator(const std::string& s) {
  if (s == "dpc") return Estimator::kDpc;
  if (s == "path_tracing") return Estimator::kPathTracing;
  return std::nullopt;
}

std::optional<DpcWeighting> parseDpcWeighting(const std::string& s) {
  if (s == "ema") return DpcWeighting::kEma;
  if (s == "seed") return DpcWeighting::kSeed;
  if (s == "window") return DpcWeighting::kWindow;
  return std::nullopt;
}

}  // namespace dpc
