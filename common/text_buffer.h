// TextBuffer: one line of text composed into a caller's fixed char array, for messages written
// where allocation is not allowed (the C API's wait-free setters, limit problems). Any thread;
// never allocates, throws or calls the OS.
#pragma once

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <string_view>

namespace dpc {

/// Appends text to out[0..size) (size >= 1), always NUL-terminated; what does not fit is cut.
class TextBuffer {
 public:
  TextBuffer(char* out, size_t size) : at_(out), end_(out + size - 1) { *at_ = '\0'; }

  TextBuffer& operator<<(std::string_view s) {
    at_ = std::copy_n(s.data(), std::min(s.size(), size_t(end_ - at_)), at_);
    *at_ = '\0';
    return *this;
  }
  /// A whole number in decimal.
  TextBuffer& operator<<(long long n) {
    char digits[24];
    return *this << std::string_view(digits,
                                     size_t(std::to_chars(digits, digits + 24, n).ptr - digits));
  }

 private:
  char* at_;
  char* const end_;
};

}  // namespace dpc
