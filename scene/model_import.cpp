#include "scene/model_import.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <sys/stat.h>

#include <algorithm>
#include <assimp/DefaultLogger.hpp>
#include <assimp/LogStream.hpp>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <mutex>
#include <optional>

#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/json_reader.h"

namespace dpc {
namespace {

/// assimp's messages may span lines; an InputError is one.
std::string oneLine(std::string s) {
  std::replace_if(
      s.begin(), s.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

/// assimp's file access with dpc's input-file rule: every file it opens (the level, a .gltf's
/// buffers) must be a regular file of at most kMaxMeshBytes; a refusal is kept for the error.
/// Exists() asks stat(), never open(): assimp's own opens the file, and a FIFO's open blocks.
class BoundedFiles : public Assimp::DefaultIOSystem {
 public:
  explicit BoundedFiles(std::string level) : level_(std::move(level)) {}
  bool Exists(const char* file) const override {
    struct stat st {};
    return ::stat(file, &st) == 0;
  }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    try {
      checkInputFile(file, kMaxMeshBytes, level_, "", "referenced file");
    } catch (const InputError& e) {
      if (!refusal_) refusal_ = e;
      return nullptr;
    }
    return DefaultIOSystem::Open(file, mode);
  }
  /// The first refusal, if any.
  const std::optional<InputError>& refusal() const { return refusal_; }

 private:
  std::string level_;
  std::optional<InputError> refusal_;
};

/// The first warning or error assimp logs that means the import changed the data ("Some faces
/// had out-of-range indices. Those faces were dropped."); other warnings are kept out.
class DroppedData : public Assimp::LogStream {
 public:
  void write(const char* message) override {
    std::string m = message;
    // "Warn,  T0: Some faces had ...": the severity and thread are not the user's concern.
    if (const size_t colon = m.find(": "); m.starts_with("Warn,") || m.starts_with("Error,"))
      if (colon != std::string::npos) m.erase(0, colon + 2);
    if (first_.empty() &&
        (m.find("dropped") != std::string::npos || m.find("out-of-range") != std::string::npos ||
         m.find("out of range") != std::string::npos))
      first_ = m;
  }
  const std::string& first() const { return first_; }

 private:
  std::string first_;
};

/// Lends `stream` to assimp's process-wide logger for one import (creating a silent logger
/// when there is none, killed again afterwards); the caller holds the import lock.
class LoggerScope {
 public:
  explicit LoggerScope(DroppedData& stream) : stream_(stream) {
    created_ = Assimp::DefaultLogger::isNullLogger();
    if (created_) Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
    Assimp::DefaultLogger::get()->attachStream(&stream_, kSeverity);
  }
  ~LoggerScope() {
    // Detached, the stream is the caller's again (assimp deletes only attached streams).
    Assimp::DefaultLogger::get()->detachStream(&stream_, kSeverity);
    if (created_) Assimp::DefaultLogger::kill();
  }
  LoggerScope(const LoggerScope&) = delete;
  LoggerScope& operator=(const LoggerScope&) = delete;

 private:
  static constexpr unsigned kSeverity = Assimp::Logger::Warn | Assimp::Logger::Err;
  DroppedData& stream_;
  bool created_ = false;
};

bool isGltf(const std::string& path) {
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return lower.ends_with(".gltf") || lower.ends_with(".glb");
}

}  // namespace

std::string gltfJsonText(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 20 || bytes.compare(0, 4, "glTF") != 0) return bytes;
  uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, 4);  // little-endian, as glTF requires
  if (bytes.compare(16, 4, "JSON") != 0 || length > bytes.size() - 20) return "";
  return bytes.substr(20, length);
}

const aiScene* importModel(Assimp::Importer& importer, const std::string& modelFile) {
  if (isGltf(modelFile)) checkJsonDepth(modelFile, gltfJsonText(modelFile));
  auto* files = new BoundedFiles(modelFile);
  importer.SetIOHandler(files);  // the importer owns it
  static std::mutex importLock;
  std::lock_guard<std::mutex> lock(importLock);
  DroppedData dropped;
  const aiScene* scene = nullptr;
  {
    LoggerScope logger(dropped);
    scene = importer.ReadFile(modelFile, aiProcess_Triangulate);
  }
  if (!scene && files->refusal()) throw *files->refusal();
  if (!scene) throw InputError(modelFile, "", oneLine(importer.GetErrorString()));
  if (!dropped.first().empty())
    throw InputError(modelFile, "",
                     "assimp read it only by changing it: " + oneLine(dropped.first()));
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode)
    throw InputError(modelFile, "", "the file holds no complete scene");
  return scene;
}

}  // namespace dpc
