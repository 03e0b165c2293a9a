// Renders SCENE.json through the dpc C++ façade into OUT.wav: the listener turns on the spot
// (one full turn) while the scene's dry signals are fed block by block through process().
// Usage: play_scene_cpp SCENE.json OUT.wav
#include <sndfile.h>

#include <chrono>
#include <cstdio>
#include <dpc/dpc.hpp>
#include <thread>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SCENE.json OUT.wav\n", argv[0]);
    return 2;
  }
  try {
    dpc::Engine engine = dpc::Engine::fromFile(argv[1]);
    const int rate = engine.sampleRate(), block = engine.blockSize();
    const int channels = engine.outputChannels();
    SF_INFO info{};
    info.samplerate = rate;
    info.channels = channels;
    info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
    SNDFILE* out = sf_open(argv[2], SFM_WRITE, &info);
    if (!out) throw std::runtime_error(std::string(argv[2]) + ": " + sf_strerror(nullptr));
    std::vector<std::vector<float>> planar(channels, std::vector<float>(block));
    std::vector<float*> outputs;
    for (auto& c : planar) outputs.push_back(c.data());
    std::vector<float> interleaved(size_t(block) * channels);

    engine.setListenerPose(0, 5.f, 1.6f, 3.5f, 0.f);
    engine.start();
    const int blocks = 4 * rate / block;  // 4 s
    for (int b = 0; b < blocks; ++b) {
      engine.setListenerPose(0, 5.f, 1.6f, 3.5f, 360.f * float(b) / float(blocks));
      std::this_thread::sleep_for(std::chrono::microseconds(1000000LL * block / rate));
      engine.process(nullptr, outputs.data(), block);
      for (int i = 0; i < block; ++i)
        for (int c = 0; c < channels; ++c) interleaved[size_t(i) * channels + c] = planar[c][i];
      sf_writef_float(out, interleaved.data(), block);
    }
    engine.stop();
    const dpc::Stats s = engine.stats();
    std::printf("%llu propagation frames, %llu impulse responses applied, %llu blocks\n",
                (unsigned long long)s.frames, (unsigned long long)s.irs_applied,
                (unsigned long long)s.blocks);
    sf_close(out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
