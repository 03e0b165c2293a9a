// The terminal in raw mode for dpc-demo --interactive: keys without Enter, no echo.
#pragma once

#include <termios.h>

namespace dpc::demo {

/// Key codes of the arrow keys as RawTerminal::key returns them.
constexpr int kKeyUp = 256 + 'U', kKeyDown = 256 + 'D', kKeyLeft = 256 + 'L', kKeyRight = 256 + 'R';

/// Standard input in raw mode (no line buffering, no echo, non-blocking reads) while the
/// object lives; restored on destruction. Does nothing if standard input is not a terminal.
/// Main thread only; not copyable.
class RawTerminal {
 public:
  RawTerminal();
  ~RawTerminal();
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;

  /// Next key, or 0 if none is waiting (never blocks). Arrow keys come back as kKeyUp,
  /// kKeyDown, kKeyLeft, kKeyRight; a lone Escape as 27. No allocation.
  int key();

 private:
  termios saved_{};
  bool active_ = false;
};

}  // namespace dpc::demo
