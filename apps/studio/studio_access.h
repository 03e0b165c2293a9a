// Who and what dpc studio's server lets in (docs/studio.md "Security"): the per-session token,
// the Origin rule and the bundled files, the only files it serves. Pure functions and one
// read-only table, so that the rules are tested without a socket (tests/apps/studio_test.cpp).
#pragma once

#include <map>
#include <string>

namespace dpc::studio {

/// A fresh session token: 32 hex digits (128 bits) from std::random_device. Allocates.
std::string newToken();

/// Whether `given` equals `token`, in time independent of where they first differ. An empty
/// token never matches.
bool tokenMatches(const std::string& given, const std::string& token);

/// Whether a request's Origin header may reach the server bound to `port`: absent (a direct
/// request, e.g. the address bar or curl) or the studio's own origin, http://127.0.0.1:PORT or
/// http://localhost:PORT. Anything else (another site's page, "null") is refused.
bool originAllowed(const std::string& origin, int port);

/// The studio's own files, read once from a folder at start: a request is answered only from
/// this table, so no path outside it (.., absolute, encoded) can reach the file system.
class BundledFiles {
 public:
  struct File {
    std::string body;
    std::string contentType;
  };
  /// Reads every regular file under `folder` (recursively; symbolic links are not followed).
  /// Throws std::runtime_error naming the folder when it has no index.html. Allocates.
  explicit BundledFiles(const std::string& folder);
  /// The file a request path names ("/" is "/index.html"), or null. A path with "..", a
  /// backslash, a '%' (a still-encoded path) or a NUL is refused before the lookup.
  const File* find(const std::string& requestPath) const;
  size_t size() const { return files_.size(); }

 private:
  std::map<std::string, File> files_;  ///< "/name" -> contents
};

}  // namespace dpc::studio
