#include "scene/model_import.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <sys/stat.h>

#include <algorithm>
#include <assimp/DefaultLogger.hpp>
#include <assimp/LogStream.hpp>
#include <mutex>
#include <optional>

#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/gltf_check.h"
#include "scene/gltf_container.h"

namespace dpc {
namespace {

/// assimp's messages may span lines; an InputError is one.
std::string oneLine(std::string s) {
  std::replace_if(
      s.begin(), s.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

/// assimp's file access under dpc's rules: the level itself, or a file inside the level's folder
/// (levelFile; assimp asks for its folder as it derives it followed by the URI as written, which
/// is percent-decoded here as glTF says and assimp 5.2 does not), each a regular file of at
/// most kMaxMeshBytes; the first refusal is kept for the error. Exists() asks stat(), never
/// open(): assimp's own opens the file, and a FIFO's open blocks.
class LevelFiles : public Assimp::DefaultIOSystem {
 public:
  explicit LevelFiles(std::string level) : level_(std::move(level)) {
    // The folder assimp's glTF reader prefixes to a URI (up to the last '/' or '\\').
    const size_t slash = level_.find_last_of("/\\");
    prefix_ = slash == std::string::npos ? "" : level_.substr(0, slash + 1);
  }
  bool Exists(const char* file) const override {
    struct stat st {};
    return ::stat(file, &st) == 0;
  }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    try {
      return DefaultIOSystem::Open(permitted(file).c_str(), mode);
    } catch (const InputError& e) {
      if (!refusal_) refusal_ = e;
      return nullptr;
    }
  }
  /// The first refusal, if any.
  const std::optional<InputError>& refusal() const { return refusal_; }

 private:
  /// The file to open for assimp's `file`, or an InputError.
  std::string permitted(const std::string& file) const {
    if (file == level_) {
      checkInputFile(file, kMaxMeshBytes, level_, "", "level file");
      return file;
    }
    if (!file.starts_with(prefix_))
      throw InputError(level_, "",
                       "referenced file '" + file + "' lies outside the level's folder");
    std::string uri = file.substr(prefix_.size());
    if (prefix_.ends_with('\\') && uri.starts_with('/')) uri.erase(0, 1);
    return levelFile(level_, "", uri, true).string();
  }

  std::string level_;
  std::string prefix_;
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

}  // namespace

const aiScene* importModel(Assimp::Importer& importer, const std::string& modelFile,
                           nlohmann::json* gltfJson) {
  if (isGltfFile(modelFile)) {
    nlohmann::json doc = checkGltfLevel(modelFile);
    if (gltfJson) *gltfJson = std::move(doc);
  }
  auto* files = new LevelFiles(modelFile);
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
