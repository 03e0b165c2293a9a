// Errors across the C API (include/dpc/dpc.h): every entry point that may fail returns a
// dpc_status; control-thread entries also keep a one-line message per calling thread, read by
// dpc_last_error() (docs/design.md "Library boundary").
#pragma once

#include <cstddef>
#include <exception>
#include <new>

#include "common/input_error.h"
#include "dpc/dpc.h"

namespace dpc::api {

/// Control thread: stores `message` as the calling thread's last error and returns `status`.
/// May allocate (the message is copied); never throws.
dpc_status fail(dpc_status status, const char* message);

/// Control thread: DPC_OK if `structSize` is `expected`, else DPC_ERR_VERSION with a message
/// naming `field` and both sizes (the caller was compiled against another dpc.h).
dpc_status checkStructSize(size_t structSize, size_t expected, const char* field);

/// Control thread: runs f (returning a dpc_status), turning its exceptions into status codes and
/// the thread's last-error text: InputError is DPC_ERR_INPUT, anything else DPC_ERR_INTERNAL.
template <class F>
dpc_status guarded(F&& f) {
  try {
    return f();
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
