#include "scene/obj_reader.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/limits.h"

namespace dpc {
namespace {

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

std::string inQuotes(const std::string& s) {
  return "\"" + s + "\"";
}

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

/// What is wrong with one vertex reference of an "f" line ("" if nothing). The forms are v,
/// v/vt, v//vn and v/vt/vn, each part a whole number within int (vt and vn may be empty):
/// tinyobjloader reads other text in part ("2.5" and "2x" as 2, "a" or "#" as 0) and wraps an
/// index beyond int.
std::string vertexReferenceProblem(const std::string& token) {
  size_t start = 0;
  for (int part = 0; part < 3; ++part) {
    const size_t slash = token.find('/', start);
    const std::string number =
        token.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    if (part == 0 || !number.empty()) {
      char* end = nullptr;
      const long long raw = std::strtoll(number.c_str(), &end, 10);
      if (number.empty() || end != number.c_str() + number.size()) break;
      if (raw > std::numeric_limits<int>::max() || raw < -std::numeric_limits<int>::max())
        return "vertex index " + number + " is out of range";
    }
    if (slash == std::string::npos) return "";
    start = slash + 1;
  }
  return inQuotes(token) +
         " is not a vertex reference (v, v/vt, v//vn or v/vt/vn, each a whole number)";
}

/// An "f" line (p after "f"): refuses what tinyobjloader would read otherwise than written,
/// and a face of fewer than 3 vertices (tinyobjloader drops a bare "f" without a word).
void checkFaceIndices(const std::string& objFile, const char* p, size_t faceNo, size_t lineNo) {
  const std::string field =
      "face " + std::to_string(faceNo) + " (line " + std::to_string(lineNo) + ")";
  std::istringstream tokens(p);
  std::string token;
  int count = 0;
  for (; tokens >> token; ++count) {
    const std::string problem = vertexReferenceProblem(token);
    if (!problem.empty()) throw InputError(objFile, field, problem);
  }
  if (count < 3) throw InputError(objFile, field, "a face needs at least 3 vertices");
}

/// One whitespace-delimited number at p (after blanks), its end in `end`; throws naming the
/// token unless all of it is a number ("7abc" is not).
double vertexNumber(const std::string& objFile, const char* p, const char*& end,
                    const std::string& field) {
  char* stop = nullptr;
  const double x = std::strtod(p, &stop);
  const size_t n = std::strcspn(p, " \t\r#");
  if (stop != p + n)
    throw InputError(objFile, field, inQuotes(std::string(p, n)) + " is not a number");
  end = stop;
  return x;
}

/// A "v" line (p after "v "): three coordinates, strtod (sees nan/inf, refuses garbage); what
/// follows may only be numbers (a weight w, or the vertex colour r g b some exporters write),
/// up to a '#' that starts a comment.
glm::vec3 parseVertex(const std::string& objFile, const char* p, const std::string& field) {
  const Limit& coordinate = limitOf("position");
  glm::vec3 v{0.f};
  const char* end = p;
  for (int i = 0; i < 3; ++i) {
    p += std::strspn(p, " \t\r");
    if (*p == '\0' || *p == '#') throw InputError(objFile, field, "expected 3 coordinates x y z");
    const double x = vertexNumber(objFile, p, end, field);
    const std::string text(p, size_t(end - p));
    if (!std::isfinite(x) || std::abs(x) > double(std::numeric_limits<float>::max()))
      throw InputError(objFile, field, "coordinate " + text + " is not finite");
    if (!withinLimit(coordinate, x))
      throw InputError(
          objFile, field,
          "coordinate " + text + " m is outside +-" + valueText(coordinate.max) + " m");
    v[i] = float(x);
    p = end;
  }
  for (p += std::strspn(p, " \t\r"); *p != '\0' && *p != '#'; p += std::strspn(p, " \t\r")) {
    vertexNumber(objFile, p, end, field);
    p = end;
  }
  return v;
}

/// Parses the "v" lines ourselves and pre-checks the "f" lines' indices.
void readObjVertices(const std::string& objFile, const std::string& text, ObjData& obj) {
  std::istringstream in(text);
  std::string line;
  size_t lineNo = 0, faceNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    const char* p = line.c_str();
    p += std::strspn(p, " \t");
    if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t' || p[1] == '\r' || p[1] == '\0')) {
      checkFaceIndices(objFile, p + 1, ++faceNo, lineNo);
      continue;
    }
    if (p[0] != 'v' || (p[1] != ' ' && p[1] != '\t')) continue;
    const std::string field = "vertex " + std::to_string(obj.vertices.size() + 1) + " (line " +
                              std::to_string(lineNo) + ")";
    obj.vertices.push_back(parseVertex(objFile, p + 2, field));
  }
}

/// tinyobjloader's callbacks: count vertices, collect faces with their usemtl slot.
tinyobj::callback_t objCallbacks() {
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
  return cb;
}

ObjData parseObj(const std::string& objFile, const std::string& text) {
  ObjData obj;
  readObjVertices(objFile, text, obj);
  const tinyobj::callback_t cb = objCallbacks();
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

/// Face fi's vertex indices resolved (1-based or relative) into positions.
std::vector<uint32_t> resolveFace(const std::string& objFile, const ObjFace& f, size_t fi,
                                  int vertexCount) {
  const std::string field = "face " + std::to_string(fi + 1);
  if (f.vertexIndex.size() < 3)
    throw InputError(objFile, field, "a face needs at least 3 vertices");
  std::vector<uint32_t> idx;
  for (int raw : f.vertexIndex) {
    const int i = raw > 0 ? raw - 1 : (raw < 0 ? f.verticesSoFar + raw : -1);
    if (raw == 0 || i < 0 || i >= vertexCount)
      throw InputError(objFile, field,
                       "vertex index " + std::to_string(raw) + " is out of range (" +
                           std::to_string(vertexCount) + " vertices)");
    idx.push_back(uint32_t(i));
  }
  return idx;
}

/// Fan-triangulates every face (convex polygons assumed) into `mesh`.
void triangulate(const std::string& objFile, const ObjData& obj, RawMesh& mesh) {
  if (obj.faces.empty()) {
    // A file of another format read as OBJ holds no faces either: say which formats are read.
    const std::string ext = std::filesystem::path(objFile).extension().string();
    std::string lower = ext;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (lower != ".obj")
      throw InputError(objFile, "",
                       "no OBJ faces in it: a mesh is read as OBJ unless it is glTF (.gltf, "
                       ".glb) or FBX (.fbx), and " +
                           (ext.empty() ? std::string("it has no extension")
                                        : inQuotes(ext) + " is none of them"));
    throw InputError(objFile, "", "mesh is empty (no faces)");
  }
  for (size_t fi = 0; fi < obj.faces.size(); ++fi) {
    const ObjFace& f = obj.faces[fi];
    const std::vector<uint32_t> idx = resolveFace(objFile, f, fi, int(obj.vertices.size()));
    const uint32_t material = f.materialSlot >= 0 ? uint32_t(f.materialSlot) : RawMesh::kNoMaterial;
    for (size_t k = 1; k + 1 < idx.size(); ++k) {
      mesh.triangles.push_back({idx[0], idx[k], idx[k + 1]});
      mesh.triangleMaterial.push_back(material);
      mesh.triangleFace.push_back(uint32_t(fi + 1));
    }
  }
}

}  // namespace

RawMesh readObj(const std::string& sceneFile, const std::string& objFile,
                const std::string& meshField) {
  checkInputFile(objFile, kMaxMeshBytes, sceneFile, meshField, "mesh file");
  std::ifstream in(objFile, std::ios::binary);
  if (!in) throw InputError(sceneFile, meshField, "cannot open mesh file " + inQuotes(objFile));
  std::stringstream buf;
  buf << in.rdbuf();
  ObjData obj = parseObj(objFile, buf.str());
  RawMesh mesh;
  mesh.file = objFile;
  triangulate(objFile, obj, mesh);
  mesh.positions = std::move(obj.vertices);
  mesh.materialNames = std::move(obj.materialNames);
  return mesh;
}

}  // namespace dpc
