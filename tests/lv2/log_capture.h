// An LV2 log feature for the plugin tests' minimal hosts (tests/lv2/lv2_rt_test.cpp) that keeps
// every line the plugin logs, from any thread but the audio thread (the plugin's loader logs).
#pragma once

#include <lv2/core/lv2.h>
#include <lv2/log/log.h>
#include <lv2/urid/urid.h>

#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

namespace dpc::test {

inline int logPrintf(LV2_Log_Handle h, LV2_URID type, const char* fmt, ...);

/// An LV2 log feature that keeps every line (any thread but the audio thread: the plugin's
/// loader logs too).
struct LogCapture {
  LogCapture() { log.printf = logPrintf; }
  std::mutex mutex;
  std::vector<std::string> lines;
  LV2_Log_Log log{this, nullptr, [](LV2_Log_Handle h, LV2_URID, const char* fmt, va_list ap) {
                    char line[4096];
                    std::vsnprintf(line, sizeof line, fmt, ap);
                    auto* capture = static_cast<LogCapture*>(h);
                    std::lock_guard lock(capture->mutex);
                    capture->lines.emplace_back(line);
                    return 0;
                  }};
  LV2_Feature feature{LV2_LOG__log, &log};
  /// The lines holding `text`, in order.
  std::vector<std::string> containing(const std::string& text) {
    std::lock_guard lock(mutex);
    std::vector<std::string> found;
    for (const std::string& line : lines)
      if (line.find(text) != std::string::npos) found.push_back(line);
    return found;
  }
};

inline int logPrintf(LV2_Log_Handle h, LV2_URID type, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  const int n = static_cast<LogCapture*>(h)->log.vprintf(h, type, fmt, ap);
  va_end(ap);
  return n;
}

}  // namespace dpc::test
