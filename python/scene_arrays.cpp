#include "python/scene_arrays.h"

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "common/input_error.h"

namespace dpc::python {
namespace {

/// Refuses an array whose shape is not rows x cols (cols 0: one-dimensional, rows any).
void requireShape(const py::array& a, const char* name, long cols) {
  const bool ok = cols == 0 ? a.ndim() == 1 : a.ndim() == 2 && a.shape(1) == cols;
  if (!ok || a.size() == 0)
    throw InputError("dpc.Engine.from_arrays", name,
                     cols == 0 ? "expected a non-empty 1-D array"
                               : "expected a non-empty N x " + std::to_string(cols) + " array");
}

/// The values of an integer array as uint32 (the C API's index type), each checked to lie in
/// [0, 2^32) so that none wraps.
template <class T>
std::vector<uint32_t> indexValues(const py::array& a, const char* name) {
  const auto values = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!values) throw py::error_already_set();
  std::vector<uint32_t> out(size_t(values.size()));
  for (size_t i = 0; i < out.size(); ++i) {
    const T v = values.data()[i];
    bool inRange = uint64_t(v) <= UINT32_MAX;
    if constexpr (std::is_signed_v<T>) inRange = v >= 0 && inRange;
    if (!inRange)
      throw InputError("dpc.Engine.from_arrays", name,
                       std::to_string(v) + " (element " + std::to_string(i) + ") is outside [0, " +
                           std::to_string(UINT32_MAX) + "]");
    out[i] = uint32_t(v);
  }
  return out;
}

/// An index argument: an array of an integer dtype whose shape is rows x cols (requireShape),
/// as uint32 values. Floats, booleans and objects are refused, not cast.
std::vector<uint32_t> indices(const py::object& given, const char* name, long cols) {
  const py::array a = py::array::ensure(given);
  if (!a) throw py::error_already_set();
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw InputError("dpc.Engine.from_arrays", name,
                     "expected an integer array, not " + std::string(py::str(a.dtype())) +
                         " (indices are not rounded)");
  requireShape(a, name, cols);
  return kind == 'i' ? indexValues<int64_t>(a, name) : indexValues<uint64_t>(a, name);
}

dpc_output_format outputFormat(const std::string& s) {
  if (s == "mono") return DPC_OUTPUT_MONO;
  if (s == "stereo") return DPC_OUTPUT_STEREO;
  if (s == "binaural") return DPC_OUTPUT_BINAURAL;
  throw InputError("dpc.Engine.from_arrays", "output",
                   "\"" + s + "\" is not one of \"mono\", \"stereo\", \"binaural\"");
}

void checkShapes(const SceneArrays& a) {
  requireShape(a.vertices, "vertices", 3);
  requireShape(a.absorption, "absorption", 8);
  requireShape(a.scattering, "scattering", 0);
  requireShape(a.sources, "sources", 3);
  requireShape(a.listener, "listener", 0);
  if (a.scattering.size() != a.absorption.shape(0))
    throw InputError("dpc.Engine.from_arrays", "scattering", "needs one per absorption row");
  if (a.listener.size() != 3)
    throw InputError("dpc.Engine.from_arrays", "listener", "expected 3 coordinates (m)");
}

/// The scene's triangles: vertex indices (T x 3) and material indices (T), checked.
struct Triangles {
  std::vector<uint32_t> vertices, materials;
};

Triangles triangles(const SceneArrays& a) {
  Triangles t{indices(a.triangles, "triangles", 3),
              indices(a.triangleMaterials, "triangle_materials", 0)};
  if (t.materials.size() * 3 != t.vertices.size())
    throw InputError("dpc.Engine.from_arrays", "triangle_materials", "needs one per triangle");
  return t;
}

}  // namespace

dpc::Engine engineFromArrays(const SceneArrays& a) {
  checkShapes(a);
  const Triangles t = triangles(a);
  std::vector<dpc_material> materials(size_t(a.absorption.shape(0)));
  for (size_t m = 0; m < materials.size(); ++m) {
    for (int b = 0; b < DPC_BANDS; ++b) materials[m].absorption[b] = a.absorption.at(m, b);
    materials[m].scattering = a.scattering.at(m);
  }
  std::vector<dpc_source> sources(size_t(a.sources.shape(0)));
  for (size_t s = 0; s < sources.size(); ++s)
    for (int k = 0; k < 3; ++k) sources[s].position[k] = a.sources.at(s, k);
  dpc_scene_data d;
  dpc_scene_data_init(&d);
  d.mesh = {a.vertices.data(), uint32_t(a.vertices.shape(0)), t.vertices.data(),
            uint32_t(t.materials.size()), t.materials.data()};
  d.materials = materials.data();
  d.material_count = int(materials.size());
  d.sources = sources.data();
  d.source_count = int(sources.size());
  for (int k = 0; k < 3; ++k) d.listener_position[k] = a.listener.at(k);
  d.listener_radius = a.listenerRadius;
  d.rays_per_frame = a.raysPerFrame;
  d.max_order = a.maxOrder;
  d.ir_length = a.irLength;
  d.seed = a.seed;
  d.sample_rate = a.sampleRate;
  d.output = outputFormat(a.output);
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;  // no dry signals: the responses are what the engine is for
  py::gil_scoped_release release;
  return dpc::Engine::fromData(d, &o);
}

}  // namespace dpc::python
