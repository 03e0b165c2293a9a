#include "api/errors.h"

#include <string>

namespace dpc::api {
namespace {

thread_local std::string lastError;

}  // namespace

dpc_status fail(dpc_status status, const char* message) {
  try {
    lastError = message;
  } catch (...) {
  }
  return status;
}

dpc_status checkStructSize(size_t structSize, size_t expected, const char* field) {
  if (structSize == expected) return DPC_OK;
  try {
    lastError = std::string(field) + ": " + std::to_string(structSize) +
                " bytes, but this library (dpc " DPC_VERSION_STRING ") expects " +
                std::to_string(expected) +
                ": compile against its dpc.h and fill the struct with its _init function";
  } catch (...) {
  }
  return DPC_ERR_VERSION;
}

}  // namespace dpc::api

extern "C" const char* dpc_last_error(void) {
  return dpc::api::lastError.c_str();
}
