#include "python/offline.h"

#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "common/input_error.h"
#include "python/arrays.h"
#include "python/errors.h"
#include "runtime/dry_signals.h"
#include "runtime/offline_renderer.h"
#include "runtime/output_format.h"
#include "runtime/session_stats.h"
#include "scene/limits.h"
#include "scene/scene.h"

namespace dpc::python {
namespace {

/// What one render heard: the rendered listener's output and its last frame's responses.
struct Render {
  OfflineListenerResult listener;
  int sampleRate = 0;
  /// The last frame's largest per-source, per-band share of the emitted energy that rays still
  /// carried when max_order ended them (FrameTotals::maxOrderEnergyFraction).
  double maxOrderEnergyFraction = 0.0;
};

/// The index of the listener called `name` (none: the first), else InputError naming it.
size_t listenerIndex(const SceneDesc& scene, const std::optional<std::string>& name) {
  if (!name) return 0;
  for (size_t i = 0; i < scene.listeners.size(); ++i)
    if (scene.listeners[i].name == *name) return i;
  throw InputError("dpc.render", "listener", "the scene has no listener \"" + *name + "\"");
}

/// The scene's settings with the overrides given (each checked against scene/limits.h).
PropagationSettings settingsFor(const SceneDesc& scene, std::optional<uint64_t> seed, int rays,
                                int threads) {
  PropagationSettings ps = scene.propagation;
  if (seed) ps.seed = *seed;
  if (rays != 0) {
    if (!withinLimit(limitOf("propagation.rays_per_frame"), rays))
      throw InputError(
          "dpc.render", "rays_per_frame",
          std::to_string(rays) + " is outside " + rangeText(limitOf("propagation.rays_per_frame")));
    ps.raysPerFrame = rays;
  }
  if (threads < 0 || threads > kMaxTracingThreads)
    throw InputError("dpc.render", "threads",
                     std::to_string(threads) + " is outside [0, " +
                         std::to_string(kMaxTracingThreads) + "] (0: all cores)");
  ps.threads = threads;
  return ps;
}

/// How often a render runs Python's signal handlers between blocks: Ctrl-C ends it within
/// about this long (plus one propagation frame), and taking the GIL this rarely costs nothing
/// measurable.
constexpr std::chrono::milliseconds kSignalCheckInterval{100};

/// OfflineOptions::sink of dpc.render: keeps every block, as the renderer would without a sink,
/// and every kSignalCheckInterval takes the GIL to run Python's signal handlers (which run on
/// the main thread only). What a handler raises (KeyboardInterrupt for Ctrl-C) ends the render
/// as py::error_already_set; nothing of it is kept.
class BlocksAndSignals {
 public:
  /// frames: the render's length, reserved once.
  BlocksAndSignals(size_t channels, size_t frames) : channels_(channels) {
    for (auto& c : channels_) c.reserve(frames);
  }
  void operator()(size_t /*listener: one rendered*/, const float* const* planar, size_t frames) {
    for (size_t c = 0; c < channels_.size(); ++c)
      channels_[c].insert(channels_[c].end(), planar[c], planar[c] + frames);
    const auto now = std::chrono::steady_clock::now();
    if (now - lastCheck_ < kSignalCheckInterval) return;
    lastCheck_ = now;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
  std::vector<std::vector<float>> take() { return std::move(channels_); }

 private:
  std::vector<std::vector<float>> channels_;
  std::chrono::steady_clock::time_point lastCheck_ = std::chrono::steady_clock::now();
};

Render render(const std::string& path, std::optional<double> duration, std::optional<uint64_t> seed,
              std::optional<std::string> listener, int rays, int threads) {
  refuseNul(path, "dpc.render", "scene");
  if (duration && !(*duration > 0 && *duration <= 86400))
    throw InputError("dpc.render", "duration", "must be in (0, 86400] s");
  std::optional<py::gil_scoped_release> release(std::in_place);
  auto scene = std::make_shared<const SceneDesc>(loadScene(path));
  const PropagationSettings ps = settingsFor(*scene, seed, rays, threads);
  OfflineOptions opt;
  opt.durationSeconds = duration.value_or(-1.0);
  opt.listener = listenerIndex(*scene, listener);
  auto dry = std::make_shared<const DrySignals>(loadDrySignals(*scene));
  const auto frames =
      size_t(std::ceil(offlineDurationSeconds(*scene, ps, *dry, opt) * scene->audio.sampleRate));
  BlocksAndSignals blocks(size_t(renderedChannels(scene->audio)), frames);
  opt.sink = std::ref(blocks);
  OfflineResult r = renderOffline(scene, ps, dry, opt);
  Render out{std::move(r.listeners.at(0)), scene->audio.sampleRate, r.last.maxOrderEnergyFraction};
  out.listener.output.channels = blocks.take();
  release.reset();
  warnMaxOrder("dpc.render: " + path, ps.maxOrder, out.maxOrderEnergyFraction,
               kMaxOrderWarnFraction);
  return out;
}

const OfflineListenerResult& checked(const Render& r, size_t source) {
  if (source >= r.listener.lastIrs.size())
    throw InputError("dpc.Render", "source",
                     std::to_string(source) + " is not a source index (the scene has " +
                         std::to_string(r.listener.lastIrs.size()) + ")");
  return r.listener;
}

}  // namespace

void bindOffline(py::module_& m) {
  py::class_<Render>(m, "Render", "What dpc.render heard: one listener's output and responses.")
      .def_readonly("sample_rate", &Render::sampleRate)
      .def_readonly("max_order_energy_fraction", &Render::maxOrderEnergyFraction,
                    "The last frame's largest per-band share of the emitted energy that rays "
                    "still carried when max_order ended them (lost; [0, 1]).")
      .def_property_readonly("listener", [](const Render& r) { return r.listener.name; })
      .def_property_readonly(
          "output",
          [](const Render& r) {
            return channelsArray(std::vector<std::vector<float>>(r.listener.output.channels));
          },
          "The rendered audio: float32 array, channels x samples (not normalised).")
      .def(
          "impulse_response",
          [](const Render& r, size_t source) {
            const ImpulseResponse& ir = checked(r, source).lastIrs[source];
            std::vector<std::vector<float>> channels;
            for (int c = 0; c < ir.channels(); ++c) channels.push_back(ir.channelCopy(c));
            return channelsArray(std::move(channels));
          },
          py::arg("source") = 0,
          "The last frame's IR of a source: float32 array, channels x samples, as dpc-demo "
          "--ir-out writes it.")
      .def(
          "energy_response",
          [](const Render& r, size_t source) {
            const auto& bins = checked(r, source).lastEnergy[source].bins();
            std::vector<float> binMajor;
            for (const Bands& bin : bins)
              for (int b = 0; b < kNumBands; ++b) binMajor.push_back(bin[b]);
            return bandsByBins(binMajor.data(), bins.size());
          },
          py::arg("source") = 0,
          "The last frame's energy response: float32 array, 8 octave bands x 1 ms bins (1/m^2).");
  m.def("render", &render, py::arg("scene"), py::arg("duration") = py::none(),
        py::arg("seed") = py::none(), py::arg("listener") = py::none(),
        py::arg("rays_per_frame") = 0, py::arg("threads") = 0,
        "Renders a scene file offline as dpc-demo --offline does (the GIL is released).");
}

}  // namespace dpc::python
