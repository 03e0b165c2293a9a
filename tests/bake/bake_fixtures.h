// The scene and settings the bake tests share: a 10 x 3 x 7 m shoebox and a quick bake
// (500 rays x 4 frames per probe, 0.5 s responses, one thread).
#pragma once

#include "bake/probe_bake.h"
#include "testing/test_scenes.h"

namespace dpc::bake::test_fixtures {

inline SceneDesc shoebox() {
  return test::makeShoebox({10.f, 3.f, 7.f}, Bands(0.2f), 0.5f, {2.f, 1.6f, 3.5f},
                           {8.f, 1.6f, 3.5f});
}

inline BakeSettings quickSettings() {
  BakeSettings s;
  s.rays = 500;
  s.frames = 4;
  s.irLength = 0.5;
  s.threads = 1;
  return s;
}

}  // namespace dpc::bake::test_fixtures
