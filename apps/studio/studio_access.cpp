#include "apps/studio/studio_access.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace dpc::studio {

std::string newToken() {
  std::random_device rd;  // /dev/urandom on Linux
  static const char kHex[] = "0123456789abcdef";
  std::string token;
  for (int i = 0; i < 4; ++i) {
    uint32_t v = rd();
    for (int k = 0; k < 8; ++k, v >>= 4) token += kHex[v & 15u];
  }
  return token;
}

bool tokenMatches(const std::string& given, const std::string& token) {
  if (token.empty() || given.size() != token.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < token.size(); ++i) diff |= (unsigned char)(given[i] ^ token[i]);
  return diff == 0;
}

bool originAllowed(const std::string& origin, int port) {
  if (origin.empty()) return true;
  const std::string p = ":" + std::to_string(port);
  return origin == "http://127.0.0.1" + p || origin == "http://localhost" + p;
}

namespace {

/// The Content-Type a browser needs for each kind of bundled file (modules must be JS).
std::string contentType(const std::filesystem::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".png") return "image/png";
  if (ext == ".json") return "application/json";
  return "text/plain; charset=utf-8";
}

std::string readAll(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

BundledFiles::BundledFiles(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_symlink() || !it->is_regular_file()) continue;
    const fs::path rel = fs::relative(it->path(), folder);
    files_["/" + rel.generic_string()] = File{readAll(it->path()), contentType(it->path())};
  }
  if (!files_.count("/index.html"))
    throw std::runtime_error("studio: " + folder +
                             ": no index.html (build the target dpc-studio-web)");
}

const BundledFiles::File* BundledFiles::find(const std::string& requestPath) const {
  if (requestPath.find("..") != std::string::npos ||
      requestPath.find_first_of(std::string("\\%\0", 3)) != std::string::npos)
    return nullptr;
  const auto it = files_.find(requestPath == "/" ? "/index.html" : requestPath);
  return it == files_.end() ? nullptr : &it->second;
}

}  // namespace dpc::studio
