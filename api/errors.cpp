#include "api/errors.h"

#include <string>

#include "common/text_buffer.h"
#include "scene/limits.h"

namespace dpc::api {
namespace {

// The calling thread's last error: control-thread entries keep any length in lastError; the
// entries that may not allocate write into fixedError. current points to the newer one.
thread_local std::string lastError;
thread_local char fixedError[256];
thread_local const char* current = nullptr;

}  // namespace

dpc_status fail(dpc_status status, const char* message) {
  try {
    lastError = message;
    current = nullptr;
  } catch (...) {
  }
  return status;
}

dpc_status failFixed(dpc_status status, const char* function, std::string_view problem) {
  TextBuffer(fixedError, sizeof fixedError) << function << ": " << problem;
  current = fixedError;
  return status;
}

bool checkArgument(const char* function, const char* argument, std::string_view field,
                   double value) {
  const Limit& limit = limitOf(field);
  if (withinLimit(limit, value)) return true;
  char problem[160];
  writeLimitProblem(limit, value, problem, sizeof problem);
  TextBuffer(fixedError, sizeof fixedError) << function << ": " << argument << ": " << problem;
  current = fixedError;
  return false;
}

dpc_status checkIndex(const char* function, const char* argument, int index, int count,
                      const char* what) {
  if (index >= 0 && index < count) return DPC_OK;
  TextBuffer(fixedError, sizeof fixedError)
      << function << ": " << argument << ": " << (long long)index << " is out of range ("
      << (long long)count << " " << what << ")";
  current = fixedError;
  return DPC_ERR_INVALID_ARGUMENT;
}

}  // namespace dpc::api

extern "C" const char* dpc_last_error(void) {
  return dpc::api::current ? dpc::api::current : dpc::api::lastError.c_str();
}
