// dpc studio's access rules (apps/studio/studio_access.h): the session token, the Origin rule
// and the bundled files, the only files the server answers from; and the studio's listener
// placement (KeyboardMotion::place).
#include "apps/studio/studio_access.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "apps/demo/keyboard_motion.h"

using namespace dpc::studio;
namespace fs = std::filesystem;

TEST_CASE("studio tokens are 128-bit, fresh each session, and compared whole") {
  const std::string a = newToken(), b = newToken();
  REQUIRE(a.size() == 32);
  REQUIRE(a.find_first_not_of("0123456789abcdef") == std::string::npos);
  REQUIRE(a != b);
  REQUIRE(tokenMatches(a, a));
  REQUIRE_FALSE(tokenMatches(b, a));
  REQUIRE_FALSE(tokenMatches(a.substr(1), a));
  REQUIRE_FALSE(tokenMatches(a + "0", a));
  REQUIRE_FALSE(tokenMatches("", ""));
}

TEST_CASE("studio origins: none or the studio's own") {
  REQUIRE(originAllowed("", 8080));
  REQUIRE(originAllowed("http://127.0.0.1:8080", 8080));
  REQUIRE(originAllowed("http://localhost:8080", 8080));
  REQUIRE_FALSE(originAllowed("http://127.0.0.1:8081", 8080));
  REQUIRE_FALSE(originAllowed("http://evil.example", 8080));
  REQUIRE_FALSE(originAllowed("null", 8080));
  REQUIRE_FALSE(originAllowed("http://127.0.0.1:8080.evil.example", 8080));
}

TEST_CASE("studio serves its bundled files and nothing else") {
  const fs::path root = fs::temp_directory_path() / ("dpc_studio_files_" + newToken());
  fs::create_directories(root / "web/vendor");
  std::ofstream(root / "web/index.html") << "<html>";
  std::ofstream(root / "web/vendor/three.module.js") << "export {}";
  std::ofstream(root / "secret.txt") << "secret";
  fs::create_symlink(root / "secret.txt", root / "web/link.txt");
  const BundledFiles files((root / "web").string());
  REQUIRE(files.size() == 2);
  REQUIRE(files.find("/")->body == "<html>");
  REQUIRE(files.find("/index.html")->contentType.rfind("text/html", 0) == 0);
  REQUIRE(files.find("/vendor/three.module.js")->contentType.rfind("text/javascript", 0) == 0);
  const std::string outside = (root / "secret.txt").string();  // outlives the loop
  for (const std::string& p : {std::string("/link.txt"), std::string("/../secret.txt"),
                               std::string("/vendor/../index.html"), std::string("/%2e%2e/secret.txt"),
                               std::string("//index.html"), std::string("/etc/passwd"),
                               std::string("\\index.html"), std::string("index.html"), outside})
    REQUIRE(files.find(p) == nullptr);
  REQUIRE_THROWS_AS(BundledFiles((root / "web/vendor").string()), std::runtime_error);
  fs::remove_all(root);
}

TEST_CASE("the studio places the played listener, which then stays put") {
  dpc::SceneDesc scene;
  dpc::ListenerDesc l;
  l.trajectory = {dpc::Keyframe{0.0, {0.f, 1.f, 0.f}, {}, {}, {}, {}},
                  dpc::Keyframe{2.0, {2.f, 1.f, 0.f}, {}, {}, {}, {}}};
  scene.listeners = {l};
  dpc::demo::KeyboardMotion motion(scene, 0);
  motion.advance(0.5);
  motion.place({5.f, 1.5f, 3.f}, 1.f);
  motion.advance(1.0);
  REQUIRE(motion.position() == glm::vec3(5.f, 1.5f, 3.f));
  REQUIRE(motion.yaw() == Approx(1.f));
  REQUIRE(motion.sceneTime() == Approx(0.5));
}
