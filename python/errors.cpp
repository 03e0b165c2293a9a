#include "python/errors.h"

#include <cmath>
#include <cstdio>

#include "common/input_error.h"
#include "dpc/dpc.hpp"

namespace dpc::python {

namespace py = pybind11;

void bindErrors(py::module_& m) {
  static py::exception<dpc::InputError> inputError(m, "InputError", PyExc_ValueError);
  static py::exception<dpc::Error> error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const dpc::InputError& e) {
      inputError(e.what());
    } catch (const dpc::Error& e) {
      // The C API's input and argument failures are the user's, like an InputError.
      if (e.status() == DPC_ERR_INPUT || e.status() == DPC_ERR_INVALID_ARGUMENT)
        inputError(e.what());
      else
        error(e.what());
    }
  });
}

void warnMaxOrder(const char* where, double share, double bound) {
  if (!(share > bound)) return;
  char message[256];
  std::snprintf(message, sizeof message,
                "%s: propagation.max_order: rays ended at their last order still carried %.2g %% "
                "of the emitted energy (%.0f dB, largest band): the decay below that is lost "
                "(T30 and the late tail read short); raise max_order",
                where, 100.0 * share, 10.0 * std::log10(share));
  if (PyErr_WarnEx(PyExc_RuntimeWarning, message, 1) != 0) throw py::error_already_set();
}

void refuseNul(const std::string& path, const char* call, const char* argument) {
  const size_t nul = path.find('\0');
  if (nul != std::string::npos)
    throw InputError(call, argument,
                     "the path holds a NUL character (at byte " + std::to_string(nul) + ")");
}

}  // namespace dpc::python
