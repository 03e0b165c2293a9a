// Raw terminal mode and key decoding (ANSI arrow-key escape sequences).
#include "apps/demo/terminal.h"

#include <poll.h>
#include <unistd.h>

namespace dpc::demo {

RawTerminal::RawTerminal() {
  if (!isatty(STDIN_FILENO) || tcgetattr(STDIN_FILENO, &saved_) != 0) return;
  termios raw = saved_;
  raw.c_lflag &= ~tcflag_t(ICANON | ECHO);
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  active_ = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
}

RawTerminal::~RawTerminal() {
  if (active_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
}

int RawTerminal::key() {
  pollfd p{STDIN_FILENO, POLLIN, 0};
  if (poll(&p, 1, 0) <= 0) return 0;
  unsigned char c = 0;
  if (read(STDIN_FILENO, &c, 1) != 1) return 0;
  if (c != 27) return c;
  unsigned char seq[2] = {0, 0};
  if (read(STDIN_FILENO, seq, 2) != 2 || seq[0] != '[') return 27;
  switch (seq[1]) {
    case 'A':
      return kKeyUp;
    case 'B':
      return kKeyDown;
    case 'C':
      return kKeyRight;
    case 'D':
      return kKeyLeft;
  }
  return 0;
}

}  // namespace dpc::demo
