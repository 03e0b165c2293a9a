#include "scene/gltf_container.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <fstream>
#include <iterator>

#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/json_reader.h"

namespace dpc {
namespace {

using nlohmann::json;

constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON", little-endian
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

uint32_t littleEndian32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

/// Reads `size` bytes at `offset`; the caller has checked that they lie within the file.
void readAt(std::ifstream& in, const std::string& file, uint64_t offset, char* out, size_t size) {
  in.seekg(std::streamoff(offset));
  if (!in.read(out, std::streamsize(size)))
    throw InputError(
        file, "",
        "cannot read " + std::to_string(size) + " bytes at offset " + std::to_string(offset));
}

void checkGlbHeader(const std::string& file, const unsigned char* header, uint64_t fileBytes) {
  if (std::memcmp(header, "glTF", 4) != 0)
    throw InputError(file, "header.magic", "is not \"glTF\": not a binary glTF (.glb) file");
  if (const uint32_t version = littleEndian32(header + 4); version != 2)
    throw InputError(file, "header.version", std::to_string(version) + "; dpc reads glTF 2.0");
  if (const uint32_t length = littleEndian32(header + 8); length != fileBytes)
    throw InputError(
        file, "header.length",
        "says " + std::to_string(length) + " bytes; the file has " + std::to_string(fileBytes));
}

/// Chunk k's header: its length within the `following` bytes of the file and a multiple of 4,
/// its type JSON first, BIN second (assimp reads no other there).
void checkChunk(const std::string& file, size_t k, uint32_t length, uint32_t type,
                uint64_t following) {
  const std::string field = index("chunks", k);
  if (length > following)
    throw InputError(file, field + ".chunkLength",
                     "is " + std::to_string(length) + " bytes; only " + std::to_string(following) +
                         " follow in the file");
  if (length % 4 != 0)
    throw InputError(file, field + ".chunkLength",
                     "is " + std::to_string(length) + ", not a multiple of 4 (chunks are aligned)");
  if (k == 0 && type != kChunkJson)
    throw InputError(file, field + ".chunkType", "is not JSON; a .glb's first chunk is its JSON");
  if (k == 1 && type != kChunkBin)
    throw InputError(file, field + ".chunkType", "is not BIN; assimp reads only a BIN chunk there");
}

/// The JSON chunk's text and the BIN chunk's length of a .glb whose size is fileBytes.
std::pair<std::string, std::optional<uint64_t>> glbChunks(const std::string& file,
                                                          uint64_t fileBytes) {
  std::ifstream in(file, std::ios::binary);
  std::array<unsigned char, 12> header{};
  if (fileBytes < header.size())
    throw InputError(
        file, "header",
        "the file is " + std::to_string(fileBytes) + " bytes, shorter than a GLB header (12)");
  readAt(in, file, 0, reinterpret_cast<char*>(header.data()), header.size());
  checkGlbHeader(file, header.data(), fileBytes);
  std::string text;
  std::optional<uint64_t> bin;
  size_t k = 0;
  for (uint64_t at = header.size(); at < fileBytes; ++k) {
    if (fileBytes - at < 8)
      throw InputError(file, index("chunks", k), "the file ends inside the chunk's header");
    unsigned char chunk[8];
    readAt(in, file, at, reinterpret_cast<char*>(chunk), 8);
    const uint32_t length = littleEndian32(chunk);
    checkChunk(file, k, length, littleEndian32(chunk + 4), fileBytes - at - 8);
    if (k == 0) {
      text.resize(length);
      readAt(in, file, at + 8, text.data(), length);
    }
    if (k == 1) bin = length;
    at += 8 + uint64_t(length);
  }
  if (k == 0) throw InputError(file, "chunks", "the file holds no JSON chunk");
  return {std::move(text), bin};
}

/// "http" for a URI that starts with a scheme (RFC 3986: a letter, then letters, digits, '+',
/// '-' or '.', then ':'), else "".
std::string uriScheme(const std::string& uri) {
  const size_t colon = uri.find(':');
  if (colon == std::string::npos || colon == 0 || !std::isalpha(uint8_t(uri[0]))) return "";
  for (size_t i = 1; i < colon; ++i)
    if (!std::isalnum(uint8_t(uri[i])) && uri[i] != '+' && uri[i] != '-' && uri[i] != '.')
      return "";
  return uri.substr(0, colon);
}

/// `uri` with its %XX escapes decoded (RFC 3986); nullopt for a malformed escape or a NUL.
std::optional<std::string> percentDecoded(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] != '%') {
      out += uri[i];
      continue;
    }
    if (i + 2 >= uri.size() || !std::isxdigit(uint8_t(uri[i + 1])) ||
        !std::isxdigit(uint8_t(uri[i + 2])))
      return std::nullopt;
    out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
    i += 2;
  }
  if (out.find('\0') != std::string::npos) return std::nullopt;
  return out;
}

/// The decoded length of "data:MEDIA;base64,DATA" with MEDIA one of `media`; refuses any other
/// form (assimp's data-URI parser keeps offsets in a char, so a long media type breaks it).
uint64_t dataUriBytes(const std::string& file, const std::string& field, const std::string& uri,
                      std::initializer_list<const char*> media) {
  const size_t comma = uri.find(',');
  const std::string head = uri.substr(0, comma);
  const bool known = std::any_of(media.begin(), media.end(), [&](const char* m) {
    return head == "data:" + std::string(m) + ";base64";
  });
  std::string allowed;
  for (const char* m : media) allowed += (allowed.empty() ? "" : " or ") + std::string(m);
  if (comma == std::string::npos || !known)
    throw InputError(file, field,
                     "a data: URI must be \"data:MEDIA;base64,...\" with MEDIA " + allowed);
  const std::string_view data = std::string_view(uri).substr(comma + 1);
  const size_t pad = data.size() - std::min(data.size(), data.find_last_not_of('=') + 1);
  const bool wellFormed = data.size() % 4 == 0 && pad <= 2 &&
                          std::all_of(data.begin(), data.end() - long(pad), [](char c) {
                            return std::isalnum(uint8_t(c)) || c == '+' || c == '/';
                          });
  if (!wellFormed) throw InputError(file, field, "the data: URI's base64 text is malformed");
  return data.size() / 4 * 3 - pad;
}

/// The level's folder as its path gives it ("" for a level in the working folder).
std::filesystem::path levelFolder(const std::string& file) {
  return std::filesystem::path(file).parent_path();
}

/// Refuses `path` unless it resolves (symbolic links followed as far as they exist) to a place
/// inside the level's folder.
void checkInsideFolder(const std::string& file, const std::string& field, const std::string& uri,
                       const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path given = levelFolder(file);
  const fs::path folder = fs::canonical(given.empty() ? fs::path(".") : given, ec);
  if (ec) throw InputError(file, field, "the level's folder cannot be resolved: " + ec.message());
  const fs::path target = fs::weakly_canonical(fs::absolute(path), ec);
  if (ec) throw InputError(file, field, "'" + uri + "' cannot be resolved: " + ec.message());
  const fs::path relative = target.lexically_relative(folder);
  if (relative.empty() || *relative.begin() == "..")
    throw InputError(file, field,
                     "'" + uri +
                         "' lies outside the level's folder; a level's files must lie in "
                         "its folder or below it");
}

}  // namespace

bool isGltfFile(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return lower.ends_with(".gltf") || lower.ends_with(".glb");
}

GltfJson readGltfJson(const std::string& file) {
  std::error_code ec;
  const uint64_t bytes = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(file, "", "cannot read its size: " + ec.message());
  std::string lower = file;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  GltfJson g;
  std::string text;
  if (lower.ends_with(".glb")) {
    std::tie(text, g.binBytes) = glbChunks(file, bytes);
  } else {
    std::ifstream in(file, std::ios::binary);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  g.doc = parseJsonText(file, text, kMaxGltfJsonValues);
  if (!g.doc.is_object())
    throw InputError(file, "",
                     "the glTF JSON is " + JsonReader::describe(g.doc) + ", not an object");
  return g;
}

std::filesystem::path levelFile(const std::string& file, const std::string& field,
                                const std::string& uri, bool mustExist) {
  if (const std::string scheme = uriScheme(uri); !scheme.empty())
    throw InputError(file, field,
                     "'" + uri + "' is a " + scheme +
                         ": URI; dpc reads only data: URIs and files in the level's folder");
  const std::optional<std::string> path = percentDecoded(uri);
  if (!path) throw InputError(file, field, "'" + uri + "' holds a malformed %-escape or a NUL");
  if (path->empty() || path->front() == '/')
    throw InputError(file, field,
                     "'" + uri + "' is " + (path->empty() ? "empty" : "an absolute path") +
                         "; a level's files are named relative to its folder");
  const std::filesystem::path full = levelFolder(file) / *path;
  checkInsideFolder(file, field, uri, full);
  if (mustExist) checkInputFile(full.string(), kMaxMeshBytes, file, field, "referenced file");
  return full;
}

uint64_t gltfBufferBytes(const std::string& file, const std::string& field, const json& buffer,
                         size_t index, const GltfJson& level) {
  const json* uri = JsonReader::find(buffer, "uri");
  if (!uri) {
    if (index == 0 && level.binBytes) return *level.binBytes;
    throw InputError(file, field + ".uri",
                     "missing; only a .glb's first buffer (its BIN chunk) has no URI");
  }
  const std::string text = JsonReader(file).string(*uri, field + ".uri");
  if (text.starts_with("data:"))
    return dataUriBytes(file, field + ".uri", text,
                        {"application/octet-stream", "application/gltf-buffer"});
  const std::filesystem::path path = levelFile(file, field + ".uri", text, true);
  std::error_code ec;
  return std::filesystem::file_size(path, ec);
}

void checkGltfImageUri(const std::string& file, const std::string& field, const std::string& uri) {
  if (uri.starts_with("data:"))
    (void)dataUriBytes(file, field, uri, {"image/png", "image/jpeg", "image/webp", "image/ktx2"});
  else
    (void)levelFile(file, field, uri, false);
}

std::vector<std::filesystem::path> gltfReferencedFiles(const std::string& file) {
  const GltfJson level = readGltfJson(file);
  std::vector<std::filesystem::path> files;
  for (const char* array : {"buffers", "images"}) {
    const json* entries = JsonReader::find(level.doc, array);
    if (!entries || !entries->is_array()) continue;
    for (const json& entry : *entries) {
      const json* uri = entry.is_object() ? JsonReader::find(entry, "uri") : nullptr;
      if (!uri || !uri->is_string() || uri->get_ref<const std::string&>().starts_with("data:"))
        continue;
      try {
        files.push_back(levelFile(file, array, uri->get<std::string>(), false));
      } catch (const InputError&) {
        // A URI levelFile refuses names no file here; loading the level refuses it.
      }
    }
  }
  return files;
}

}  // namespace dpc
