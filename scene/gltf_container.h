// The outside of a glTF 2.0 level, checked before assimp reads it: a .glb's container (its
// header and every chunk length against the file's size, before anything is allocated for a
// chunk), the JSON under bounded depth and value count, and the files its URIs name (a
// data: URI, or a relative path that resolves inside the level's folder; never a network URI,
// an absolute path or a symbolic link leading out). Private to scene/ (scene/gltf_check.h and
// scene/model_import.cpp); docs/scene-format.md ("glTF and FBX levels") is the user's view.
//
// Any thread that loads a scene; allocates; throws InputError(level file, field, problem).
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace dpc {

/// Largest number of JSON values (objects, arrays, numbers, strings, literals) in a level's
/// JSON: a parsed value costs about 50-100 bytes, so this keeps the parse under ~400 MB; a
/// large game level (50,000 nodes, 200,000 accessors) holds about 2 million.
inline constexpr size_t kMaxGltfJsonValues = size_t(1) << 22;

/// A level's JSON and, for a .glb, its BIN chunk's length.
struct GltfJson {
  nlohmann::json doc;
  std::optional<uint64_t> binBytes;  ///< bytes in a .glb's BIN chunk (none: no BIN chunk)
};

/// True when `path` ends in .gltf or .glb (any case).
bool isGltfFile(const std::string& path);

/// The JSON of `file`, a regular file already checked against kMaxMeshBytes. A .glb (binary
/// as its extension says, as assimp decides): magic "glTF", version 2, header length equal to
/// the file's size, every chunk's length within the file and a multiple of 4, the first
/// chunk JSON, a second one BIN; each refusal names the header or chunk field
/// ("chunks[0].chunkLength"). The JSON: at most kMaxJsonDepth deep, kMaxGltfJsonValues values,
/// no repeated key, an object.
GltfJson readGltfJson(const std::string& file);

/// The bytes a buffer's data holds: a data: URI's decoded length (the URI must be
/// "data:application/octet-stream;base64,..." or "data:application/gltf-buffer;base64,...",
/// base64 well formed), a referenced file's size (levelFile with mustExist), or, for a .glb's
/// first buffer without a URI, its BIN chunk's length. `field` is "buffers[i]".
uint64_t gltfBufferBytes(const std::string& file, const std::string& field,
                         const nlohmann::json& buffer, size_t index, const GltfJson& level);

/// Checks an image's URI: a data: URI of an image media type, or a path that levelFile accepts
/// (it need not exist: dpc never reads images). `field` is "images[i].uri".
void checkGltfImageUri(const std::string& file, const std::string& field, const std::string& uri);

/// The files that level `file` (.gltf or .glb) names in its buffers' and images' URIs, each
/// resolved as levelFile resolves it (not data: URIs; a URI levelFile refuses is left out, as
/// loading the level refuses it). For the list of a run's inputs, which no output may
/// overwrite. Throws InputError when the level's JSON cannot be read.
std::vector<std::filesystem::path> gltfReferencedFiles(const std::string& file);

/// The file a URI of level `file` names: percent-decoded (RFC 3986), relative to the level's
/// folder. Refuses a URI with a scheme (http:, ftp:, file:, ...: dpc never fetches, and never
/// maps one to a local file), an absolute path, a malformed escape or a NUL, and a path that
/// resolves (symbolic links followed) outside the level's folder; with mustExist, also
/// anything but an existing regular file of at most kMaxMeshBytes. Nothing is opened.
/// Errors name `field`.
std::filesystem::path levelFile(const std::string& file, const std::string& field,
                                const std::string& uri, bool mustExist);

}  // namespace dpc
