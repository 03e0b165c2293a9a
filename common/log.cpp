#include "common/log.h"

#include <cstdio>
#include <mutex>
#include <utility>

namespace dpc {
namespace {

/// The process's sink and the lock that serialises it with its replacement.
struct LogState {
  std::mutex mutex;
  LogSink sink;
};

LogState& state() {
  static LogState s;
  return s;
}

void printToStderr(LogLevel level, const char* message) {
  std::fprintf(stderr, "%s%s\n", level == LogLevel::kWarning ? "warning: " : "", message);
}

}  // namespace

void setLogSink(LogSink sink) {
  LogState& s = state();
  const std::lock_guard<std::mutex> lock(s.mutex);
  s.sink = std::move(sink);
}

void logMessage(LogLevel level, const std::string& message) {
  LogState& s = state();
  const std::lock_guard<std::mutex> lock(s.mutex);
  try {
    if (s.sink)
      s.sink(level, message.c_str());
    else
      printToStderr(level, message.c_str());
  } catch (...) {
  }
}

}  // namespace dpc
