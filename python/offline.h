// dpc.render: a scene rendered offline exactly as `dpc-demo SCENE --offline` renders it (the
// same runtime/offline_renderer.h call, so the same seed gives the same bits), with the last
// frame's impulse and energy responses. Private to python/.
#pragma once

#include <pybind11/pybind11.h>

namespace dpc::python {

/// Registers dpc.render and the dpc.Render result type.
void bindOffline(pybind11::module_& m);

}  // namespace dpc::python
