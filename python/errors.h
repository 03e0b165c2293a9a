// Python exceptions of the module: dpc.InputError (a ValueError) for a bad scene, file or
// argument, carrying dpc's one-line message ("FILE: FIELD: problem"); dpc.Error (a
// RuntimeError) for anything else the library reports. Private to python/.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

namespace dpc::python {

/// Registers the exception types and the translators from dpc::InputError and dpc::Error.
void bindErrors(pybind11::module_& m);

/// Refuses a path holding a NUL character (dpc::InputError "CALL: ARGUMENT: ..."): the C
/// calls below would open the path cut at the NUL, another file than the one named.
void refuseNul(const std::string& path, const char* call, const char* argument);

/// Issues a RuntimeWarning (once per call; Python's filters decide whether it shows or
/// raises) when the rays max_order ended still carried more than `bound` of the emitted
/// energy (`share`, largest band): the decay below that level is missing from the response.
/// `where`: the call and the scene file ("dpc.render: room.json"); `maxOrder` as
/// dpc::maxOrderWarning (<= 0: not known here). Needs the GIL; throws py::error_already_set
/// when the warnings filter turns it into an exception.
void warnMaxOrder(const std::string& where, int maxOrder, double share, double bound);

}  // namespace dpc::python
