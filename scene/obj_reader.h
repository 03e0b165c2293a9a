// Wavefront OBJ reader: positions, triangles and usemtl names as the file has them, with no
// cleaning (degenerate triangles stay; scene/mesh_builder.h drops them).
//
// Control thread; allocates; throws InputError naming the OBJ file and the vertex or face (or
// the scene file and its key when the OBJ cannot be opened). Why tinyobjloader's callback
// parser: its LoadObj drops usemtl names it cannot find in a .mtl file, and we want the names
// alone (the .mtl may be absent). Why "v" lines are parsed here as well: tinyobjloader reads
// "nan", "abc" and missing coordinates as 0 without a word; we refuse them with the vertex
// number and line.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <string>
#include <vector>

namespace dpc {

/// A triangle soup before cleaning. Polygons are fan-triangulated (convex assumed); every
/// index is in range. Coordinates are metres, finite and within the coordinate limit.
struct RawMesh {
  /// triangleMaterial value of a triangle whose face came before any usemtl.
  static constexpr uint32_t kNoMaterial = std::numeric_limits<uint32_t>::max();

  std::vector<glm::vec3> positions;
  std::vector<std::array<uint32_t, 3>> triangles;  ///< indices into positions
  std::vector<uint32_t> triangleMaterial;          ///< per triangle: index into materialNames
  std::vector<std::string> materialNames;          ///< usemtl names in order of first use
  /// Per triangle, the number users know its face by (1-based OBJ face), for messages.
  std::vector<uint32_t> triangleFace;
  std::string faceWord = "face";  ///< what triangleFace counts ("face", "triangle")
  std::string materialWord = "usemtl";  ///< what names a material in the file, for messages
  std::string file;               ///< the file (or API structure) messages name
};

/// Reads `objFile` (at most kMaxMeshBytes). sceneFile and meshField ("mesh",
/// "objects[2].mesh") name the scene key that points at it, for errors about the file itself.
RawMesh readObj(const std::string& sceneFile, const std::string& objFile,
                const std::string& meshField);

}  // namespace dpc
