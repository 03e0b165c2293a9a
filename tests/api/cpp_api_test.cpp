// The C++ façade (include/dpc/dpc.hpp): errors as dpc::Error, options, step and response
// read-out through std::vector.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "dpc/dpc.hpp"

TEST_CASE("C++ API: options, step and responses of the shoebox") {
  CHECK_THROWS_AS(dpc::Engine::fromFile("/nonexistent/scene.json"), dpc::Error);
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.sample_rate = 44100;
  o.block_size = 128;
  o.output = DPC_OUTPUT_STEREO;
  o.rays_per_frame = 512;
  o.host_inputs_only = 1;  // the scene's speech.wav is not read
  dpc::Engine e = dpc::Engine::fromFile(DPC_SOURCE_DIR "/scenes/shoebox.json", &o);
  CHECK(e.sampleRate() == 44100);
  CHECK(e.blockSize() == 128);
  CHECK(e.outputChannels() == 2);
  CHECK_THROWS_AS(e.impulseResponse(0, 0), dpc::Error);  // no frame yet
  e.step();
  // ir_length 2 s at the overridden rate; 2000 energy bins of 1 ms.
  CHECK(e.impulseResponse(0, 1).size() == size_t(2.0 * 44100));
  double bin = 0.0;
  const std::vector<float> er = e.energyResponse(0, &bin);
  CHECK(er.size() == 2000 * DPC_BANDS);
  CHECK(bin == 1e-3);
  double total = 0.0;
  for (float v : er) total += v;
  CHECK(std::isfinite(total));
  CHECK(total > 0.0);
}
