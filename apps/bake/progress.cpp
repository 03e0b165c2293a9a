#include "apps/bake/progress.h"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace dpc::bake {

Progress::Progress(size_t total, size_t already, bool quiet, const char* unit)
    : total_(total),
      already_(already),
      quiet_(quiet),
      terminal_(::isatty(STDERR_FILENO) != 0),
      unit_(unit),
      start_(std::chrono::steady_clock::now()) {}

double Progress::elapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double Progress::rate() const {
  const double t = elapsedSeconds();
  return done_ > 0 && t > 0.0 ? double(done_) / t : 0.0;
}

void Progress::step() {
  ++done_;
  if (quiet_) return;
  const int decile = total_ ? int(10 * done_ / total_) : 10;
  if (terminal_ || decile != lastDecile_) draw();
  lastDecile_ = decile;
}

void Progress::stepTo(size_t done, size_t total) {
  done_ = done;
  total_ = total;
  if (quiet_) return;
  const int decile = total_ ? int(10 * done_ / total_) : 10;
  const double now = elapsedSeconds();
  if (terminal_ ? now - lastDraw_ >= kRedrawSeconds || done_ == total_ : decile != lastDecile_) {
    draw();
    lastDraw_ = now;
  }
  lastDecile_ = decile;
}

void Progress::draw() const {
  constexpr int kWidth = 30;
  const int filled = total_ ? int(kWidth * done_ / total_) : kWidth;
  const std::string bar = std::string(size_t(filled), '#') + std::string(size_t(kWidth - filled), '.');
  const double r = rate();
  const double eta = r > 0.0 ? double(total_ - done_) / r : 0.0;
  std::fprintf(stderr, "%s[%s] %zu/%zu %s, %.2f %s/s, ETA %.0f s%s", terminal_ ? "\r" : "",
               bar.c_str(), already_ + done_, already_ + total_, unit_, r, unit_, eta,
               terminal_ ? "   " : "\n");
  std::fflush(stderr);
}

void Progress::finish() {
  if (!quiet_ && terminal_) std::fprintf(stderr, "\n");
}

}  // namespace dpc::bake
