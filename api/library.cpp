// Library-wide entries of the C API: the version and the log callback (include/dpc/dpc.h).
#include "common/log.h"
#include "dpc/dpc.h"

static_assert(int(dpc::LogLevel::kInfo) == DPC_LOG_INFO &&
                  int(dpc::LogLevel::kWarning) == DPC_LOG_WARNING &&
                  int(dpc::LogLevel::kError) == DPC_LOG_ERROR,
              "dpc_log_level mirrors dpc::LogLevel");

extern "C" {

unsigned long dpc_version(void) {
  return DPC_VERSION;
}

void dpc_set_log_callback(dpc_log_callback callback, void* user_data) {
  try {
    if (!callback) {
      dpc::setLogSink({});
      return;
    }
    dpc::setLogSink([callback, user_data](dpc::LogLevel level, const char* message) {
      callback(dpc_log_level(level), message, user_data);
    });
  } catch (...) {
    // A two-pointer lambda fits std::function's inline storage: no allocation that could fail.
  }
}

}  // extern "C"
