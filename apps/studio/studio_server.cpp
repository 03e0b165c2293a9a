#include "apps/studio/studio_server.h"

#include <httplib.h>

#include <bit>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "apps/studio/studio_access.h"
#include "apps/studio/studio_ir.h"
#include "apps/studio/studio_json.h"
#include "common/input_error.h"

namespace dpc::studio {

/// Request worker threads. A browser opens up to 6 connections while the page loads, and a
/// kept-alive connection holds its worker until it closes: fewer workers left the page's
/// module requests queued for whole keep-alive periods on a loaded machine.
constexpr size_t kWorkerThreads = 8;
/// Seconds an idle kept-alive connection holds its worker.
constexpr time_t kKeepAliveSeconds = 1;
/// Largest coordinate the page may send, m: anything beyond is a bad request, not a place.
constexpr double kMaxCoordinate = 1e5;

struct StudioServer::Impl {
  ServerOptions options;
  StudioBoard& board;
  BundledFiles files;
  httplib::Server http;
  std::thread thread;
  int port = 0;
  /// The newest /api/ir document and the IR it describes: its IACC costs tens of ms, and the
  /// page and a test may ask for the same frame's IR more than once.
  std::mutex irMutex;
  std::shared_ptr<const StudioIr> irDone;
  std::shared_ptr<const std::string> irDoneJson;

  Impl(const ServerOptions& o, StudioBoard& b) : options(o), board(b), files(o.webFolder) {}

  std::string cookieName() const { return "dpc_studio_" + std::to_string(port); }
  bool authorised(const httplib::Request& req, bool& fromQuery) const;
  void routeReads();
  void routeIr();
  std::shared_ptr<const std::string> irDocument(const std::shared_ptr<const StudioIr>& ir);
  void routeAudio();
  void routeWrites();
  void routeFiles();
};

namespace {

using httplib::Request;
using httplib::Response;
using nlohmann::json;

/// The value of cookie `name` in a Cookie header, or "".
std::string cookieValue(const std::string& header, const std::string& name) {
  const std::string key = name + "=";
  for (size_t at = header.find(key); at != std::string::npos; at = header.find(key, at + 1))
    if (at == 0 || header[at - 1] == ' ' || header[at - 1] == ';') {
      const size_t from = at + key.size();
      return header.substr(from, header.find(';', from) - from);
    }
  return "";
}

/// A position [x, y, z] within kMaxCoordinate, or nothing.
std::optional<glm::vec3> position(const json& j) {
  if (!j.is_array() || j.size() != 3) return std::nullopt;
  glm::vec3 p;
  for (int i = 0; i < 3; ++i) {
    if (!j[i].is_number() || !(std::abs(j[i].get<double>()) <= kMaxCoordinate)) return std::nullopt;
    p[i] = j[i].get<float>();
  }
  return p;
}

/// The frame number of "?frame=N".
uint64_t frameParam(const Request& req) {
  return std::strtoull(req.get_param_value("frame").c_str(), nullptr, 10);
}

void refuse(Response& res, int status, const char* why) {
  res.status = status;
  res.set_content(std::string(why) + "\n", "text/plain");
}

/// Parses a POST body as JSON; false (400 sent) when it is not.
bool parseBody(const Request& req, Response& res, json& body) {
  body = json::parse(req.body, nullptr, false);
  if (body.is_discarded() || !body.is_object()) refuse(res, 400, "body: not a JSON object");
  return !body.is_discarded() && body.is_object();
}

}  // namespace

bool StudioServer::Impl::authorised(const Request& req, bool& fromQuery) const {
  fromQuery = tokenMatches(req.get_param_value("token"), options.token);
  return fromQuery || tokenMatches(req.get_header_value("X-Dpc-Token"), options.token) ||
         tokenMatches(cookieValue(req.get_header_value("Cookie"), cookieName()), options.token);
}

/// GET /api/...: the scene, the bake's maps (404 without --bake), and a frame's state,
/// response or CSV (the newest, or ?frame=N).
void StudioServer::Impl::routeReads() {
  auto withFrame = [this](auto body) {
    return [this, body](const Request& req, Response& res) {
      auto f = req.has_param("frame") ? board.find(frameParam(req)) : board.latest();
      if (!f) return refuse(res, 404, "no such frame (yet)");
      body(*f, res);
    };
  };
  http.Get("/api/scene", [this](const Request&, Response& res) {
    res.set_content(*board.scene(), "application/json");
  });
  http.Get("/api/bake", [this](const Request&, Response& res) {
    const auto bake = board.bake();
    if (!bake) return refuse(res, 404, "no bake (dpc-demo runs without --bake)");
    res.set_content(*bake, "application/json");
  });
  http.Get("/api/state", withFrame([](const StudioFrame& f, Response& res) {
             res.set_content(stateJson(f), "application/json");
           }));
  http.Get("/api/response", withFrame([](const StudioFrame& f, Response& res) {
             res.set_content(responseJson(f), "application/json");
           }));
  http.Get("/api/energy.csv", withFrame([](const StudioFrame& f, Response& res) {
             res.set_content(energyCsv(f), "text/csv");
           }));
}

std::shared_ptr<const std::string> StudioServer::Impl::irDocument(
    const std::shared_ptr<const StudioIr>& ir) {
  {
    std::lock_guard<std::mutex> lock(irMutex);
    if (irDone == ir) return irDoneJson;
  }
  auto text = std::make_shared<const std::string>(irJson(*ir));  // outside the lock
  std::lock_guard<std::mutex> lock(irMutex);
  irDone = ir;
  irDoneJson = text;
  return text;
}

/// GET /api/ir and /api/ir.wav: the selected pair's IR of a kept frame (the newest, or ?frame=N).
void StudioServer::Impl::routeIr() {
  auto withIr = [this](auto body) {
    return [this, body](const Request& req, Response& res) {
      auto ir = req.has_param("frame") ? board.findIr(frameParam(req)) : board.latestIr();
      if (!req.has_param("frame")) board.wantIr();  // the next frame's IR for the next request
      if (!ir) return refuse(res, 404, "no such IR (yet)");
      body(ir, res);
    };
  };
  http.Get("/api/ir", withIr([this](const std::shared_ptr<const StudioIr>& ir, Response& res) {
             res.set_content(*irDocument(ir), "application/json");
           }));
  http.Get("/api/ir.wav", withIr([](const std::shared_ptr<const StudioIr>& ir, Response& res) {
             res.set_content(irWav(*ir), "audio/wav");
           }));
}

/// GET /api/audio?from=N: the offline clock's sound from frame N on (StudioAudio::since; no N:
/// from the newest on), as little-endian float32 interleaved samples; the headers X-Dpc-First,
/// X-Dpc-Skipped, X-Dpc-Sample-Rate and X-Dpc-Channels say what they are. 409 when there is
/// none to play.
void StudioServer::Impl::routeAudio() {
  http.Get("/api/audio", [this](const Request& req, Response& res) {
    const std::shared_ptr<StudioAudio> audio = board.audio();
    if (!audio)
      return refuse(res, 409, "no sound to play in the page: the audio device plays this session, "
                              "or its output is not mono, stereo or binaural");
    // No "from": the newest frame on (an empty chunk that says where the sound stands).
    const uint64_t from = req.has_param("from")
                              ? std::strtoull(req.get_param_value("from").c_str(), nullptr, 10)
                              : UINT64_MAX;
    const StudioAudio::Chunk c = audio->since(from);
    res.set_header("X-Dpc-First", std::to_string(c.first));
    res.set_header("X-Dpc-Skipped", std::to_string(c.skipped));
    res.set_header("X-Dpc-Sample-Rate", std::to_string(audio->sampleRate()));
    res.set_header("X-Dpc-Channels", std::to_string(audio->channels()));
    res.set_header("Cache-Control", "no-store");
    static_assert(std::endian::native == std::endian::little, "float32 little-endian on the wire");
    res.set_content(std::string(reinterpret_cast<const char*>(c.interleaved.data()),
                                c.interleaved.size() * sizeof(float)),
                    "application/octet-stream");
  });
}

/// POST /api/...: the page's requests, checked, left on the board for the control loop.
void StudioServer::Impl::routeWrites() {
  http.Post("/api/listener", [this](const Request& req, Response& res) {
    json body;
    if (!parseBody(req, res, body)) return;
    const auto p = position(body.value("position", json()));
    const double yaw = body.value("yaw", 0.0);
    if (!p || !std::isfinite(yaw)) return refuse(res, 400, "listener: position [x, y, z], yaw");
    board.requestListener({*p, float(yaw)});
    res.set_content("{}", "application/json");
  });
  http.Post("/api/source", [this](const Request& req, Response& res) {
    json body;
    if (!parseBody(req, res, body)) return;
    const auto p = position(body.value("position", json()));
    const size_t index = body.value("index", size_t(-1));
    if (!p || index >= options.sourceCount)
      return refuse(res, 400, "source: index (scene order), position [x, y, z]");
    board.requestSource(index, *p);
    res.set_content("{}", "application/json");
  });
  http.Post("/api/select", [this](const Request& req, Response& res) {
    json body;
    if (!parseBody(req, res, body)) return;
    const size_t index = body.value("source", size_t(-1));
    if (index >= options.sourceCount) return refuse(res, 400, "select: source (scene order)");
    board.select(index);
    res.set_content("{}", "application/json");
  });
}

void StudioServer::Impl::routeFiles() {
  http.Get("/.*", [this](const Request& req, Response& res) {
    const BundledFiles::File* f = files.find(req.path);
    if (!f) return refuse(res, 404, "not a file of the studio");
    res.set_content(f->body, f->contentType.c_str());
    res.set_header("Cache-Control", "no-store");
  });
}

StudioServer::StudioServer(const ServerOptions& options, StudioBoard& board)
    : impl_(std::make_unique<Impl>(options, board)) {
  Impl& s = *impl_;
  s.http.new_task_queue = [] { return new httplib::ThreadPool(kWorkerThreads); };
  s.http.set_keep_alive_timeout(kKeepAliveSeconds);
  // Every request: the Origin rule, then the token; the first page load sets the cookie the
  // page's module imports carry (they cannot carry the query).
  s.http.set_pre_routing_handler([&s](const Request& req, Response& res) {
    using R = httplib::Server::HandlerResponse;
    if (!originAllowed(req.get_header_value("Origin"), s.port))
      return refuse(res, 403, "foreign origin"), R::Handled;
    bool fromQuery = false;
    if (!s.authorised(req, fromQuery)) return refuse(res, 403, "token required"), R::Handled;
    if (fromQuery)
      res.set_header("Set-Cookie", s.cookieName() + "=" + s.options.token +
                                       "; Path=/; HttpOnly; SameSite=Strict");
    return R::Unhandled;
  });
  s.routeReads();
  s.routeIr();
  s.routeAudio();
  s.routeWrites();
  s.routeFiles();
  s.port = options.port == 0 ? s.http.bind_to_any_port(options.host)
                             : (s.http.bind_to_port(options.host, options.port) ? options.port : -1);
  if (s.port < 0)
    throw InputError("command line", "--port",
                     "cannot listen on " + options.host + ":" + std::to_string(options.port) +
                         " (in use, or not an address of this machine)");
  s.thread = std::thread([&s] { s.http.listen_after_bind(); });
}

StudioServer::~StudioServer() {
  impl_->http.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

int StudioServer::port() const { return impl_->port; }

std::string StudioServer::url() const {
  return "http://" + impl_->options.host + ":" + std::to_string(impl_->port) +
         "/?token=" + impl_->options.token;
}

}  // namespace dpc::studio
