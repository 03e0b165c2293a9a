// One logging function for the library's warnings and messages (docs/design.md "Library
// boundary"): library code calls logMessage; the sink decides where the line goes. The default
// sink prints to stderr; the C API replaces it with the host's callback (dpc_set_log_callback).
//
// Threads: any thread but the audio thread (logging takes a lock and the sink may allocate or
// block). Calls are serialised: the sink runs under the lock, one message at a time, and must
// not call setLogSink itself. The sink runs on the logging thread: the control thread for the
// C API's messages; JACK's own thread for the messages JACK hands dpc-demo's audio device
// (audio/output_backend.cpp), as JACK's default printer would.
#pragma once

#include <functional>
#include <string>

namespace dpc {

/// Severity of a message; the values are those of the C API's dpc_log_level.
enum class LogLevel {
  kInfo = 0,
  kWarning = 1,
  kError = 2,
};

/// Receives one message: a single line without a trailing newline, valid during the call.
using LogSink = std::function<void(LogLevel level, const char* message)>;

/// Any thread but the audio thread. Sends every later message to `sink`; an empty sink
/// restores the default (stderr, "warning: " before a warning). Copies the sink (may allocate;
/// throws std::bad_alloc only then).
void setLogSink(LogSink sink);

/// Any thread but the audio thread. Hands `message` (one line) to the sink. Does not allocate
/// itself; never throws (a throwing sink's exception is swallowed).
void logMessage(LogLevel level, const std::string& message);

}  // namespace dpc
