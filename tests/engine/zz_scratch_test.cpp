#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <glm/gtc/quaternion.hpp>
#include "scene/scene.h"
#include "tests/engine/door_scenes.h"
using namespace dpc;
using namespace dpc::door_test;
TEST_CASE("zz two rooms door", "[zz]") {
  SceneDesc base = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/two_rooms.json");
  const glm::vec3 src(2.f, 1.6f, 2.f);
  const glm::vec3 lis(10.5f, 1.6f, 3.8f);
  const float deg = std::atof(std::getenv("DEG"));
    SceneDesc s = base;
    s.objects[0].trajectory.resize(1);
    s.objects[0].trajectory[0].rotation = glm::angleAxis(glm::radians(deg), glm::vec3(0, 1, 0));
    const Bands m = decibels(directLevel(std::getenv("OBJ") ? s : objectsInMesh(s), src, lis));
    std::printf("%4.0f deg mesh:", double(deg));
    for (int b = 0; b < 5; ++b) std::printf(" %6.1f", double(m[b]));
    std::printf("\n");
}
