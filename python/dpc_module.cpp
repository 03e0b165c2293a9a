// The Python module `dpc` (pybind11): scenes rendered offline as dpc-demo renders them, an
// engine stepped frame by frame with poses set from Python (the C++ facade of the C API,
// include/dpc/dpc.hpp), and ISO 3382-1 parameters of impulse responses. Arrays cross as numpy
// arrays: the responses are moved into them, not copied. The GIL is released while tracing.
// Errors become dpc.InputError (a ValueError: the scene's or an argument's one-line message,
// "FILE: FIELD: problem") or dpc.Error (a RuntimeError). docs/python.md is the user's guide.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "analysis/room_parameters.h"
#include "common/bands.h"
#include "common/input_error.h"
#include "dpc/dpc.hpp"
#include "python/arrays.h"
#include "python/errors.h"
#include "python/offline.h"
#include "python/scene_arrays.h"

namespace py = pybind11;

namespace dpc::python {
namespace {

/// Per band and broadband: T20, T30, EDT (s), C50, C80 (dB), D50, energy, as numpy arrays of
/// kNumBands values plus a "broadband" dict of numbers.
py::dict iso3382(const py::array_t<float, py::array::c_style | py::array::forcecast>& ir,
                 int sampleRate) {
  if (ir.ndim() != 1) throw py::value_error("iso3382: ir must be one-dimensional (samples)");
  if (sampleRate < 1) throw py::value_error("iso3382: sample_rate must be positive (Hz)");
  if (ir.size() == 0) throw py::value_error("iso3382: ir is empty");
  // As dpc-analyze refuses such a WAV: one NaN or infinity would make every parameter NaN.
  for (py::ssize_t i = 0; i < ir.size(); ++i)
    if (!std::isfinite(ir.data()[i]))
      throw py::value_error("iso3382: ir[" + std::to_string(i) +
                            "] is not finite (NaN or infinity)");
  audio::ImpulseResponseAnalysis a;
  {
    py::gil_scoped_release release;
    a = audio::analyzeImpulseResponse(ir.data(), size_t(ir.size()), sampleRate);
  }
  using Field = double audio::RoomParameters::*;
  const std::pair<const char*, Field> fields[] = {
      {"t20", &audio::RoomParameters::t20},
      {"t30", &audio::RoomParameters::t30},
      {"edt", &audio::RoomParameters::edt},
      {"c50", &audio::RoomParameters::c50},
      {"c80", &audio::RoomParameters::c80},
      {"d50", &audio::RoomParameters::d50},
      {"energy", &audio::RoomParameters::energy},
      {"inr", &audio::RoomParameters::inrDb},
      {"truncation", &audio::RoomParameters::truncationSeconds}};
  py::dict out, broadband;
  for (const auto& [name, field] : fields) {
    std::vector<double> perBand(kNumBands);
    for (int b = 0; b < kNumBands; ++b) perBand[size_t(b)] = a.bands[size_t(b)].*field;
    out[name] = vectorArray(std::move(perBand), {size_t(kNumBands)});
    broadband[name] = a.broadband.*field;
  }
  out["bands_hz"] = std::vector<float>(kBandCentreHz.begin(), kBandCentreHz.end());
  out["broadband"] = broadband;
  return out;
}

/// dpc.Engine's object: the engine and the lock of its step() calls. dpc.h makes
/// dpc_engine_step a control-thread call (one thread at a time) while the copies and pose
/// setters may run beside it; step() releases the GIL, so two Python threads stepping one
/// engine would otherwise run it at once (heap corruption). The lock is taken after the GIL is
/// released: a thread waiting for it holds no lock another thread needs.
class PyEngine : public dpc::Engine {
 public:
  /// `where`: the warning's prefix (the call and, for a scene file, its path); `maxOrder`:
  /// the engine's max_order where the caller set it, else 0.
  PyEngine(dpc::Engine&& e, std::string where, int maxOrder)
      : dpc::Engine(std::move(e)), where_(std::move(where)), maxOrder_(maxOrder) {}
  /// One frame; warns (once an engine) when max_order cut more than its bound.
  void step() {
    double cut = 0.0;
    {
      py::gil_scoped_release release;
      const std::lock_guard<std::mutex> lock(stepMutex_);
      dpc::Engine::step();
      cut = stats().max_order_energy_fraction;
    }
    if (maxOrderWarned_ || !(cut > DPC_MAX_ORDER_WARN_FRACTION)) return;
    maxOrderWarned_ = true;  // under the GIL
    warnMaxOrder(where_, maxOrder_, cut, DPC_MAX_ORDER_WARN_FRACTION);
  }
  /// dpc_stats.max_order_energy_fraction of the last frame.
  double maxOrderEnergyFraction() {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(stepMutex_);
    return stats().max_order_energy_fraction;
  }
  /// dpc_stats.frames. stats() is a control-thread call, as step() is: under the same lock.
  uint64_t frames() {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(stepMutex_);
    return stats().frames;
  }

 private:
  std::mutex stepMutex_;
  const std::string where_;
  const int maxOrder_;
  bool maxOrderWarned_ = false;
};

/// The pose setters: the C API's message names the argument and its limit ("x: 1e+07 is
/// outside [-1000000, 1000000] m").
void checkPose(dpc_status s, const char* what) {
  if (s == DPC_OK) return;
  const std::string message = dpc_last_error();  // "dpc_engine_set_...: ARGUMENT: problem"
  const size_t colon = message.find(": ");
  throw InputError("dpc.Engine", what,
                   colon == std::string::npos ? message : message.substr(colon + 2));
}

void setListenerPose(PyEngine& e, int listener, const std::array<float, 3>& p, float yaw,
                     float pitch, float roll) {
  checkPose(e.setListenerPose(listener, p[0], p[1], p[2], yaw, pitch, roll), "set_listener_pose");
}

void setSourcePosition(PyEngine& e, int source, const std::array<float, 3>& p) {
  checkPose(e.setSourcePosition(source, p[0], p[1], p[2]), "set_source_position");
}

void teleportSource(PyEngine& e, int source) {
  checkPose(e.teleportSource(source), "teleport_source");
}

void teleportListener(PyEngine& e, int listener) {
  checkPose(e.teleportListener(listener), "teleport_listener");
}

/// rotation: a quaternion (x, y, z, w), glTF order (docs/design.md "One frame for every pose").
void setObjectPose(PyEngine& e, int object, const std::array<float, 3>& p,
                   const std::array<float, 4>& q) {
  checkPose(e.setObjectPose(object, p[0], p[1], p[2], q[0], q[1], q[2], q[3]), "set_object_pose");
}

/// The engine's responses of one source as numpy arrays.
py::array engineIr(PyEngine& e, int source) {
  std::vector<std::vector<float>> channels;
  for (int c = 0; c < e.irChannels(); ++c) channels.push_back(e.impulseResponse(source, c));
  return channelsArray(std::move(channels));
}

py::array engineEnergy(PyEngine& e, int source) {
  std::vector<float> er = e.energyResponse(source);  // bin-major: [bin][band]
  return bandsByBins(er.data(), er.size() / kNumBands);
}

std::unique_ptr<PyEngine> openEngine(const std::string& scene, int rays) {
  refuseNul(scene, "dpc.Engine", "scene");
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.rays_per_frame = rays;
  py::gil_scoped_release release;  // loads meshes and signals, builds the BVH
  return std::make_unique<PyEngine>(dpc::Engine::fromFile(scene, &o), "dpc.Engine.step: " + scene,
                                    0);
}

std::unique_ptr<PyEngine> fromArrays(FloatArray vertices, py::object triangles,
                                     py::object triangleMaterials, FloatArray absorption,
                                     FloatArray scattering, FloatArray sources, FloatArray listener,
                                     float listenerRadius, int rays, int maxOrder, float irLength,
                                     uint64_t seed, int sampleRate, std::string output) {
  return std::make_unique<PyEngine>(
      engineFromArrays({vertices, triangles, triangleMaterials, absorption, scattering, sources,
                        listener, listenerRadius, rays, maxOrder, irLength, seed, sampleRate,
                        std::move(output)}),
      "dpc.Engine.step", maxOrder);
}

/// numpy, which every response is returned as. Without it the import fails with an ImportError
/// that says so and names the interpreter (pybind11 would report only "initialization failed",
/// the reason hidden in the chained exception): thrown as a C++ exception, whose text
/// PYBIND11_MODULE passes on as the ImportError's.
void importNumpy() {
  try {
    py::module_::import("numpy");
  } catch (py::error_already_set& e) {
    const std::string python = py::str(py::module_::import("sys").attr("executable"));
    throw std::runtime_error("dpc needs numpy, which " + python + " cannot import (" +
                             e.what() + "); install it for that interpreter (Debian: "
                             "python3-numpy; a venv: python3 -m venv --system-site-packages)");
  }
}

void bindEngine(py::module_& m) {
  dpc_scene_data defaults;  // from_arrays's defaults are a scene file's (the C API's)
  dpc_scene_data_init(&defaults);
  py::class_<PyEngine>(m, "Engine", R"(A scene's engine, stepped one propagation frame at a
time from Python (the C API's dpc_engine): set poses, step(), read the responses.)")
      .def(py::init(&openEngine), py::arg("scene"), py::arg("rays_per_frame") = 0,
           "Loads a scene file; rays_per_frame 0 keeps the scene's.")
      .def_static("from_arrays", &fromArrays, py::arg("vertices"), py::arg("triangles"),
                  py::arg("triangle_materials"), py::arg("absorption"), py::arg("scattering"),
                  py::arg("sources"), py::arg("listener"), py::arg("listener_radius") = 0.5f,
                  py::arg("rays_per_frame") = defaults.rays_per_frame,
                  py::arg("max_order") = defaults.max_order,
                  py::arg("ir_length") = defaults.ir_length, py::arg("seed") = defaults.seed,
                  py::arg("sample_rate") = 48000,
                  py::arg("output") = "mono",
                  "A scene from arrays (m, octave bands 63 Hz .. 8 kHz); no dry signals.")
      // Getters as lambdas on PyEngine: pybind11 2.10 (Debian 12) binds a noexcept member of
      // the base dpc::Engine with `self` typed as dpc::Engine, a type it does not know, so
      // every call raised TypeError (its method_adaptor has no noexcept overloads).
      .def_property_readonly("sample_rate", [](const PyEngine& e) { return e.sampleRate(); },
                             "Hz")
      .def_property_readonly("block_size", [](const PyEngine& e) { return e.blockSize(); },
                             "frames of one audio block")
      .def_property_readonly("output_channels",
                             [](const PyEngine& e) { return e.outputChannels(); })
      .def_property_readonly("ir_channels", [](const PyEngine& e) { return e.irChannels(); },
                             "rows of impulse_response()")
      .def_property_readonly("source_count", [](const PyEngine& e) { return e.sourceCount(); })
      .def_property_readonly("listener_count",
                             [](const PyEngine& e) { return e.listenerCount(); })
      .def_property_readonly("object_count", [](const PyEngine& e) { return e.objectCount(); })
      .def_property_readonly("frames", &PyEngine::frames,
                             "Propagation frames traced so far (step() adds one).")
      .def_property_readonly("max_order_energy_fraction", &PyEngine::maxOrderEnergyFraction,
                             "The last frame's largest per-band share of the emitted energy "
                             "that rays still carried when max_order ended them (lost; [0, 1]).")
      .def("set_listener_pose", &setListenerPose, py::arg("listener"), py::arg("position"),
           py::arg("yaw_degrees") = 0.f, py::arg("pitch_degrees") = 0.f,
           py::arg("roll_degrees") = 0.f)
      .def("set_source_position", &setSourcePosition, py::arg("source"), py::arg("position"))
      .def("set_object_pose", &setObjectPose, py::arg("object"), py::arg("position"),
           py::arg("rotation"))
      .def("teleport_source", &teleportSource, py::arg("source"),
           "The source jumped: its cached paths are dropped at the next frame.")
      .def("teleport_listener", &teleportListener, py::arg("listener"),
           "The listener jumped: its cached paths are dropped at the next frame.")
      .def("step", &PyEngine::step,
           "Traces one propagation frame now (the GIL is released meanwhile; steps of one "
           "engine from several threads run one at a time).")
      .def("impulse_response", &engineIr, py::arg("source") = 0,
           "The newest IR of the played listener: float32 array, channels x samples.")
      .def("energy_response", &engineEnergy, py::arg("source") = 0,
           "The newest energy response: float32 array, 8 octave bands x 1 ms bins (1/m^2).");
}

}  // namespace
}  // namespace dpc::python

PYBIND11_MODULE(dpc, m) {
  m.doc() = "dpc: interactive sound propagation (diffuse path cache). docs/python.md";
  // pybind11 2.10 looks numpy's C API up once, in a static local, when the first array is made;
  // two threads making their first arrays at once deadlock there (one holds the static's guard
  // and waits for the GIL, the other holds the GIL and waits for the guard). numpy imported
  // and one array made here, while the module loads on one thread, do that lookup now.
  dpc::python::importNumpy();
  py::array_t<float>(0);
  dpc::python::bindErrors(m);
  dpc::python::bindEngine(m);
  dpc::python::bindOffline(m);
  m.def("iso3382", &dpc::python::iso3382, py::arg("ir"), py::arg("sample_rate"),
        "ISO 3382-1 parameters of a 1-D impulse response (dict of per-band arrays).");
  m.attr("BANDS_HZ") = std::vector<float>(dpc::kBandCentreHz.begin(), dpc::kBandCentreHz.end());
}
