// dpc.Engine.from_arrays: a scene built from numpy arrays (the C API's dpc_scene_data, which
// checks every value as a scene file's are checked). Private to python/.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "dpc/dpc.hpp"

namespace dpc::python {

namespace py = pybind11;

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// The scene's numbers; shapes are checked (dpc.InputError naming the argument), values by the
/// C API (dpc.InputError naming the dpc_scene_data field).
struct SceneArrays {
  FloatArray vertices;  ///< V x 3, m
  /// The index arrays: any array-like of an integer dtype (no cast: a float index would be
  /// truncated), every value in [0, 2^32).
  py::object triangles;          ///< T x 3 vertex indices
  py::object triangleMaterials;  ///< T material indices
  FloatArray absorption;         ///< M x 8, per octave band 63 Hz .. 8 kHz, [0, 1]
  FloatArray scattering;         ///< M, [0, 1]
  FloatArray sources;            ///< S x 3 positions, m
  FloatArray listener;           ///< 3, m
  float listenerRadius = 0.5f;   ///< m
  // Set by Engine.from_arrays, whose defaults are a scene file's (PropagationSettings).
  int raysPerFrame = 0;
  int maxOrder = 0;
  float irLength = 0.f;  ///< s
  uint64_t seed = 0;
  int sampleRate = 48000;       ///< Hz
  std::string output = "mono";  ///< "mono", "stereo" or "binaural"
};

/// An engine without dry signals (its responses are what it is for). Releases the GIL while
/// the engine is built.
dpc::Engine engineFromArrays(const SceneArrays& a);

}  // namespace dpc::python
