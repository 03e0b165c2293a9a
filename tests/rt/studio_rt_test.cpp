// The audio thread's rule with dpc studio open: the real-time test's live session renders with
// no heap call on its audio thread while the control thread serves the studio as dpc-demo does
// (StudioHost: a StudioFrame with the pair's responses, paths, edges, poses and the heat map's
// surfaces published after every new frame, the page's requests applied) and a "page" thread
// polls the server's routes over HTTP as studio/web/studio.js does. The session keeps the
// surfaces' energy (LiveSession::Options::keepSurfaceEnergy) as a studio session does.
#include <httplib.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <memory>
#include <regex>
#include <string>
#include <thread>

#include "alloc_counter.h"
#include "apps/demo/studio_host.h"
#include "live_driver.h"

using namespace dpc;

namespace {

/// Serves dpc studio from the driver's control loop, with a page polling it over HTTP.
struct StudioOpen {
  demo::Flags flags;
  std::unique_ptr<demo::StudioHost> host;
  std::unique_ptr<demo::KeyboardMotion> motion;
  std::thread page;
  std::atomic<bool> stop{false};
  std::atomic<int> answered{0};  ///< page requests answered 200

  void configure(LiveSession::Options& o) { o.keepSurfaceEnergy = true; }

  void step(const SceneDesc& scene, LiveSession& session) {
    if (!host) start(scene, session);
    host->applyRequests(*motion, session);
    host->publish(session, *motion, studio::StudioFigures{});
  }

  void start(const SceneDesc& scene, LiveSession& session) {
    host = std::make_unique<demo::StudioHost>(scene, flags);
    motion = std::make_unique<demo::KeyboardMotion>(scene, session.playedListener());
    std::smatch m;
    const std::string url = host->url();
    REQUIRE(std::regex_search(url, m, std::regex(R"(:(\d+)/\?token=([0-9a-f]+))")));
    page = std::thread([this, port = std::stoi(m[1]), token = m[2].str()] {
      httplib::Client client("127.0.0.1", port);
      const httplib::Headers h{{"X-Dpc-Token", token}};
      while (!stop.load()) {
        for (const char* route : {"/api/state", "/api/response", "/api/ir"})
          if (auto r = client.Get(route, h); r && r->status == 200) ++answered;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
  }

  void finish() {
    stop = true;
    if (page.joinable()) page.join();
    host.reset();
  }
};

}  // namespace

TEST_CASE("LiveSession::render makes no heap calls with dpc studio open", "[rt]") {
  rt::CountHeapCalls counter;
  const uint64_t swaps = 50;
  StudioOpen studio;
  const test::LiveRun run = test::driveLiveSession(2000, swaps, counter, 0, Rendering::kAuto,
                                                   OutputFormat::kBinaural, false, studio);
  CHECK(counter.calls == 0);
  CHECK(run.status.irsApplied >= swaps);
  CHECK(run.finite);
  // The page really read frames and IRs while the audio thread rendered.
  CHECK(studio.answered.load() >= 10);
}
