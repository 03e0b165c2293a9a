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

}  // namespace dpc::python
