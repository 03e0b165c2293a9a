// The outermost frame of dpc's programs: runs a program's body and turns an escaping exception
// into one line on stderr and exit status 1, so that every error looks alike ("dpc-demo:
// FILE: FIELD: problem" for bad input, "dpc-demo: error: ..." for anything else); a run
// stopped by a signal (common/stop_signals.h) exits with 128 + its number after
// "dpc-demo: interrupted by SIGINT". Control thread (main); the message costs an allocation;
// never throws.
#pragma once

#include <cstdio>
#include <exception>

#include "common/input_error.h"
#include "common/stop_signals.h"

namespace dpc {

/// body() -> int (the exit status); `program` prefixes the error line.
template <typename Body>
int runReportingErrors(const char* program, Body&& body) noexcept {
  try {
    return body();
  } catch (const Interrupted& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return 128 + e.signal();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
  } catch (...) {
    std::fprintf(stderr, "%s: error: unknown exception\n", program);
  }
  return 1;
}

}  // namespace dpc
