#include "scene/model_reader.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstring>

#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/json_reader.h"
#include "scene/limits.h"
#include "scene/model_animation.h"
#include "scene/model_import.h"
#include "scene/quaternion.h"

namespace dpc {
namespace {

std::string quoted(const aiString& s) {
  return inQuotes(s.C_Str());
}

/// The rotation, scale and position of `m`, the transform of a moving object's node or of its
/// parent (`whose`); refuses one without a rotation: a zero or non-finite scale.
Trs decompose(const aiMatrix4x4& m, const std::string& file, const aiNode& node,
              const char* whose) {
  aiVector3D s, p;
  aiQuaternion q;
  m.Decompose(s, q, p);
  const std::optional<glm::quat> rotation = unitQuaternion(q.x, q.y, q.z, q.w);
  const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  if (!rotation || !finite || !(s.x * s.y * s.z != 0.f) || !std::isfinite(s.x * s.y * s.z))
    throw InputError(file, "node " + quoted(node.mName),
                     std::string(whose) +
                         " transform has a zero or non-finite scale, so it holds no rotation; a "
                         "moving object needs a rigid frame");
  Trs out;
  out.position = glm::vec3(p.x, p.y, p.z);
  out.rotation = *rotation;
  out.scale = glm::vec3(s.x, s.y, s.z);
  return out;
}

/// Everything the node walk needs and builds.
struct Walk {
  const aiScene* scene = nullptr;
  std::string file;
  const std::vector<ModelObjectRequest>* requests = nullptr;
  RawModel out;
  std::vector<const aiNode*> nodes;      // per request, the node found
  std::vector<aiMatrix4x4> parentWorld;  // per request, the node's parent's world transform
  uint32_t triangles = 0;                // numbers triangles for messages
};

uint32_t materialSlot(const Walk& w, const aiMesh& m, RawMesh& raw) {
  const std::string name = w.scene->mMaterials[m.mMaterialIndex]->GetName().C_Str();
  if (name.empty() || name == AI_DEFAULT_MATERIAL_NAME) return RawMesh::kNoMaterial;
  const auto it = std::find(raw.materialNames.begin(), raw.materialNames.end(), name);
  if (it != raw.materialNames.end()) return uint32_t(it - raw.materialNames.begin());
  raw.materialNames.push_back(name);
  return uint32_t(raw.materialNames.size() - 1);
}

glm::vec3 vertex(const Walk& w, const aiMesh& m, unsigned i, const aiMatrix4x4& toFrame) {
  const aiVector3D& v = m.mVertices[i];
  const std::string field = "mesh " + quoted(m.mName) + " vertex " + std::to_string(i + 1);
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw InputError(w.file, field, "coordinate is NaN or infinite (in its accessor)");
  const aiVector3D p = toFrame * v;
  const Limit& coordinate = limitOf("position");
  for (const float x : {p.x, p.y, p.z})
    if (!withinLimit(coordinate, x))
      throw InputError(w.file, field,
                       "coordinate " + valueText(x) + " m (transformed) is outside +-" +
                           valueText(coordinate.max) + " m");
  return glm::vec3(p.x, p.y, p.z);
}

/// Appends one assimp mesh, transformed by toFrame, to `raw`. A mirroring toFrame (negative
/// determinant) reverses each triangle's corners, as glTF says: a mirror turns the winding, and
/// the faces keep their front side only with it reversed again.
void appendMesh(Walk& w, const aiMesh& m, const aiMatrix4x4& toFrame, RawMesh& raw) {
  if (m.mPrimitiveTypes & (aiPrimitiveType_POINT | aiPrimitiveType_LINE))
    throw InputError(w.file, "mesh " + quoted(m.mName),
                     "has point or line primitives; dpc needs triangles");
  const uint32_t base = uint32_t(raw.positions.size());
  for (unsigned i = 0; i < m.mNumVertices; ++i) raw.positions.push_back(vertex(w, m, i, toFrame));
  const uint32_t slot = materialSlot(w, m, raw);
  const bool mirrored = toFrame.Determinant() < 0;
  for (unsigned f = 0; f < m.mNumFaces; ++f) {
    const aiFace& face = m.mFaces[f];
    if (face.mNumIndices != 3 ||
        std::max({face.mIndices[0], face.mIndices[1], face.mIndices[2]}) >= m.mNumVertices)
      throw InputError(w.file, "mesh " + quoted(m.mName) + " face " + std::to_string(f + 1),
                       "is not a triangle of the mesh's vertices");
    raw.triangles.push_back({base + face.mIndices[0], base + face.mIndices[mirrored ? 2 : 1],
                             base + face.mIndices[mirrored ? 1 : 2]});
    raw.triangleMaterial.push_back(slot);
    raw.triangleFace.push_back(++w.triangles);
  }
}

int requestOf(const Walk& w, const aiNode& node) {
  for (size_t k = 0; k < w.requests->size(); ++k)
    if ((*w.requests)[k].name == node.mName.C_Str()) return int(k);
  return -1;
}

/// Visits `node` whose parent's world transform is parentWorld. owner: the request whose
/// subtree this is (-1: the static world), toOwner: the parent's transform into its frame.
void visit(Walk& w, const aiNode& node, const aiMatrix4x4& parentWorld, int owner,
           const aiMatrix4x4& toOwner) {
  const int request = requestOf(w, node);
  aiMatrix4x4 toFrame = toOwner * node.mTransformation;
  if (request >= 0) {
    const ModelObjectRequest& r = (*w.requests)[size_t(request)];
    if (w.nodes[size_t(request)])
      throw InputError(w.file, "node " + quoted(node.mName),
                       "two nodes are named so (" + r.field + ")");
    if (owner >= 0)
      throw InputError(w.file, "node " + quoted(node.mName),
                       "lies inside the moving object " + (*w.requests)[size_t(owner)].name +
                           "; objects cannot be nested");
    w.nodes[size_t(request)] = &node;
    w.parentWorld[size_t(request)] = parentWorld;
    owner = request;
    toFrame = aiMatrix4x4();  // the node's own meshes are in its own frame
  }
  RawMesh& raw = owner < 0 ? w.out.world : w.out.objects[size_t(owner)].mesh;
  const aiMatrix4x4 world = parentWorld * node.mTransformation;
  for (unsigned i = 0; i < node.mNumMeshes; ++i)
    appendMesh(w, *w.scene->mMeshes[node.mMeshes[i]], owner < 0 ? world : toFrame, raw);
  for (unsigned i = 0; i < node.mNumChildren; ++i)
    visit(w, *node.mChildren[i], world, owner, toFrame);
}

/// An empty mesh whose messages name the model file, its triangles and materials.
RawMesh modelMesh(const std::string& file) {
  RawMesh raw;
  raw.file = file;
  raw.faceWord = "triangle";
  raw.materialWord = "material";
  return raw;
}

/// FBX: UnitScaleFactor is centimetres per file unit; refuses an up axis other than y. glTF
/// carries neither (metres, y up).
float unitScale(const aiScene& scene, const std::string& file) {
  if (!scene.mMetaData) return 1.f;
  int up = 1;
  if (scene.mMetaData->Get("UpAxis", up) && up != 1)
    throw InputError(file, "UpAxis",
                     "is " + std::string(up == 2 ? "z" : "x") +
                         "; dpc's frame is y up: export the FBX with Y up");
  float cmPerUnitF = 0.f;
  double cmPerUnit = 100.0;
  if (scene.mMetaData->Get("UnitScaleFactor", cmPerUnitF))
    cmPerUnit = cmPerUnitF;
  else
    (void)scene.mMetaData->Get("UnitScaleFactor", cmPerUnit);
  // A zero scale collapses the level; a negative one mirrors it (and turns its faces inside out).
  if (!(cmPerUnit > 0.0) || !std::isfinite(float(cmPerUnit / 100.0)))
    throw InputError(file, "UnitScaleFactor",
                     valueText(cmPerUnit) +
                         " is not a unit length (centimetres per unit, > 0): zero would collapse "
                         "the level and a negative value mirror it");
  return float(cmPerUnit / 100.0);
}

/// Per request, its node's channel (channel == nullptr: not animated). Refuses a channel on a
/// node no request names and a node moved by two animations.
std::vector<NodeChannel> channels(const Walk& w, const std::map<std::string, GltfNode>& gltf) {
  std::vector<NodeChannel> out(w.requests->size());
  for (unsigned a = 0; a < w.scene->mNumAnimations; ++a) {
    const aiAnimation& anim = *w.scene->mAnimations[a];
    for (unsigned c = 0; c < anim.mNumChannels; ++c) {
      const aiNodeAnim* ch = anim.mChannels[c];
      const std::string node = ch->mNodeName.C_Str();
      const auto r = std::find_if(w.requests->begin(), w.requests->end(),
                                  [&](const ModelObjectRequest& q) { return q.name == node; });
      const std::string field = "animation " + quoted(anim.mName);
      if (r == w.requests->end())
        throw InputError(w.file, field,
                         "moves node " + quoted(ch->mNodeName) +
                             ", which the scene does not name in \"objects\" (only objects move)");
      NodeChannel& out1 = out[size_t(r - w.requests->begin())];
      if (out1.channel)
        throw InputError(w.file, field,
                         "moves node " + quoted(ch->mNodeName) + " as does " + "animation \"" +
                             out1.animation + "\"; dpc plays one");
      out1.channel = ch;
      out1.animation = anim.mName.C_Str();
      out1.ticksPerSecond = anim.mTicksPerSecond > 0 ? anim.mTicksPerSecond : 1.0;
      if (const auto it = gltf.find(node); it != gltf.end()) out1.gltf = &it->second;
    }
  }
  return out;
}

/// The node's pose and local triangles in the world frame: world = parent * node(t) * local,
/// parent = position + rotation * (uniform scale * x).
void finishObject(const Walk& w, size_t k, const std::map<std::string, GltfNode>& gltf,
                  NodeChannel channel, ModelObject& object) {
  const ModelObjectRequest& r = (*w.requests)[k];
  const Trs parent = decompose(w.parentWorld[k], w.file, *w.nodes[k], "its parent's");
  const float sp = parent.scale.x;
  if (std::abs(parent.scale.y - sp) > 1e-5f * sp || std::abs(parent.scale.z - sp) > 1e-5f * sp)
    throw InputError(w.file, "node " + quoted(w.nodes[k]->mName),
                     "its parent's scale is not uniform; a moving object needs a rigid frame");
  const auto node = gltf.find(r.name);
  const Trs own = node != gltf.end() && node->second.trs
                      ? *node->second.trs
                      : decompose(w.nodes[k]->mTransformation, w.file, *w.nodes[k], "its");
  channel.rest.position = own.position;
  channel.rest.rotation = own.rotation;
  channel.restScale = own.scale;
  NodeKeys keys;
  if (channel.channel) {
    keys = readNodeKeys(channel, w.file);
  } else {
    keys.keys.push_back(channel.rest);
    keys.scale = own.scale;
  }
  for (ObjectKeyframe& key : keys.keys) {
    key.position = parent.position + parent.rotation * (sp * key.position);
    key.rotation = parent.rotation * key.rotation;
  }
  for (glm::vec3& p : object.mesh.positions) p *= sp * keys.scale;
  if (keys.scale.x * keys.scale.y * keys.scale.z < 0)  // mirrored: the winding reversed back
    for (auto& t : object.mesh.triangles) std::swap(t[1], t[2]);
  object.name = r.name;
  object.trajectory = std::move(keys.keys);
}

}  // namespace

bool isModelFile(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* ext : {".gltf", ".glb", ".fbx"})
    if (lower.size() > std::strlen(ext) && lower.ends_with(ext)) return true;
  return false;
}

RawModel readModel(const std::string& sceneFile, const std::string& modelFile,
                   const std::string& meshField, const std::vector<ModelObjectRequest>& requests) {
  checkInputFile(modelFile, kMaxMeshBytes, sceneFile, meshField, "mesh file");
  Assimp::Importer importer;
  // FBX pivots as separate helper nodes would take a node's animation away from its name.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  nlohmann::json gltfJson;
  const aiScene* scene = importModel(importer, modelFile, &gltfJson);
  Walk w;
  w.scene = scene;
  w.file = modelFile;
  w.requests = &requests;
  w.out.objects.resize(requests.size());
  w.nodes.assign(requests.size(), nullptr);
  w.parentWorld.resize(requests.size());
  w.out.world = modelMesh(modelFile);
  for (ModelObject& o : w.out.objects) o.mesh = modelMesh(modelFile);
  aiMatrix4x4 units;
  aiMatrix4x4::Scaling(aiVector3D(unitScale(*scene, modelFile)), units);
  visit(w, *scene->mRootNode, units, -1, aiMatrix4x4());
  const std::map<std::string, GltfNode> gltf = readGltfNodes(gltfJson);
  const std::vector<NodeChannel> moves = channels(w, gltf);
  for (size_t k = 0; k < requests.size(); ++k) {
    if (!w.nodes[k])
      throw InputError(sceneFile, requests[k].field,
                       "no node named \"" + requests[k].name + "\" in " + modelFile);
    finishObject(w, k, gltf, moves[k], w.out.objects[k]);
  }
  return std::move(w.out);
}

}  // namespace dpc
