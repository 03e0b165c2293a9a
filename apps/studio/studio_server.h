// StudioServer: dpc studio's web server (cpp-httplib, HTTP/1.1; the page polls JSON, no
// WebSocket: Debian's cpp-httplib has none). It runs on a thread of its own, answers from the
// StudioBoard and the bundled files only, and checks every request: the session token (query
// "token", header "X-Dpc-Token", or the cookie the first page load sets), the Origin header
// (studio_access.h). docs/studio.md lists the routes.
#pragma once

#include <memory>
#include <string>

#include "apps/studio/studio_board.h"

namespace dpc::studio {

struct ServerOptions {
  std::string host = "127.0.0.1";  ///< the address to bind (loopback unless asked otherwise)
  int port = 0;                    ///< 0: any free port
  std::string webFolder;           ///< the bundled page (BundledFiles)
  std::string token;               ///< the session's token (newToken())
  /// Sources the page may move or select (scene.sources.size()).
  size_t sourceCount = 0;
};

class StudioServer {
 public:
  /// Control thread: reads the bundled files, binds host:port and starts serving on a thread
  /// of its own. Throws InputError naming --port when the port cannot be bound, and
  /// std::runtime_error when the page's files are missing. Allocates.
  StudioServer(const ServerOptions& options, StudioBoard& board);
  /// Control thread: stops serving and joins the thread.
  ~StudioServer();
  StudioServer(const StudioServer&) = delete;
  StudioServer& operator=(const StudioServer&) = delete;

  /// The port bound (the one asked for, or the one the system chose for 0).
  int port() const;
  /// http://HOST:PORT/?token=TOKEN
  std::string url() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dpc::studio
