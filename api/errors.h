// Errors across the C API (include/dpc/dpc.h): every entry point that may fail returns a
// dpc_status; control-thread entries also keep a one-line message per calling thread, read by
// dpc_last_error() (docs/design.md "Library boundary").
#pragma once

#include <cstddef>
#include <exception>
#include <new>
#include <string_view>

#include "common/input_error.h"
#include "dpc/dpc.h"

namespace dpc::api {

/// Control thread: stores `message` as the calling thread's last error and returns `status`.
/// May allocate (the message is copied); never throws.
dpc_status fail(dpc_status status, const char* message);

/// Any thread; no allocation (the text goes into the calling thread's fixed message buffer):
/// stores "FUNCTION: PROBLEM" as the thread's last error and returns `status`. For entry points
/// that may not allocate (wait-free setters); the text is cut at 255 bytes.
dpc_status failFixed(dpc_status status, const char* function, std::string_view problem);

/// Any thread; no allocation: true if `value` lies within limitOf(field) (scene/limits.h), else
/// stores "FUNCTION: ARGUMENT: PROBLEM" (the validator's wording, e.g. "1e+20 is outside
/// [-1000000, 1000000] m") as the thread's last error and returns false.
bool checkArgument(const char* function, const char* argument, std::string_view field,
                   double value);

/// Any thread; no allocation: DPC_OK if 0 <= index < count, else DPC_ERR_INVALID_ARGUMENT with
/// "FUNCTION: ARGUMENT: INDEX is out of range (COUNT WHAT)" as the thread's last error.
dpc_status checkIndex(const char* function, const char* argument, int index, int count,
                      const char* what);

/// A NULL pointer inside a caller's struct where its count says there is data (the caller's
/// mistake in calling, not in the scene): DPC_ERR_INVALID_ARGUMENT, worded as an InputError.
struct NullArgument : dpc::InputError {
  using dpc::InputError::InputError;
};

/// Control thread: runs f (returning a dpc_status), turning its exceptions into status codes and
/// the thread's last-error text: NullArgument is DPC_ERR_INVALID_ARGUMENT, any other InputError
/// DPC_ERR_INPUT, anything else DPC_ERR_INTERNAL.
template <class F>
dpc_status guarded(F&& f) {
  try {
    return f();
  } catch (const NullArgument& e) {
    return fail(DPC_ERR_INVALID_ARGUMENT, e.what());
  } catch (const dpc::InputError& e) {
    return fail(DPC_ERR_INPUT, e.what());
  } catch (const std::bad_alloc&) {
    return fail(DPC_ERR_INTERNAL, "out of memory");
  } catch (const std::exception& e) {
    return fail(DPC_ERR_INTERNAL, e.what());
  } catch (...) {
    return fail(DPC_ERR_INTERNAL, "unknown error");
  }
}

}  // namespace dpc::api
