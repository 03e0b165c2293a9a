#include "python/errors.h"

#include "common/input_error.h"
#include "dpc/dpc.hpp"
#include "runtime/max_order_warning.h"

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

void warnMaxOrder(const std::string& where, int maxOrder, double share, double bound) {
  if (!(share > bound)) return;
  const std::string message = where + ": " + maxOrderWarning(maxOrder, share);
  if (PyErr_WarnEx(PyExc_RuntimeWarning, message.c_str(), 1) != 0) throw py::error_already_set();
}

void refuseNul(const std::string& path, const char* call, const char* argument) {
  const size_t nul = path.find('\0');
  if (nul != std::string::npos)
    throw InputError(call, argument,
                     "the path holds a NUL character (at byte " + std::to_string(nul) + ")");
}

}  // namespace dpc::python
