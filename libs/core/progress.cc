#include "core/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace jvl {

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const auto total = static_cast<int64_t>(std::llround(seconds));
  const int64_t h = total / 3600, m = (total / 60) % 60, s = total % 60;
  char buf[48];
  if (h > 0) {
    std::snprintf(buf, sizeof(buf), "%lld:%02lld:%02lld", static_cast<long long>(h),
                  static_cast<long long>(m), static_cast<long long>(s));
  } else {
    std::snprintf(buf, sizeof(buf), "%lld:%02lld", static_cast<long long>(m),
                  static_cast<long long>(s));
  }
  return buf;
}

Progress::Progress(std::string name, int64_t total, bool enabled)
    : name_(std::move(name)), total_(total), active_(enabled && isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
  if (active_ && done_.load() > 0) Print(true);
}

std::string Progress::Line() const {
  const int64_t done = done_.load();
  const double elapsed = timer_.ElapsedSeconds();
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  const double eta = rate > 0 ? (total_ - done) / rate : NAN;
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%s %lld/%lld  %.1f frames/s  ETA %s", name_.c_str(),
                static_cast<long long>(done), static_cast<long long>(total_), rate,
                FormatDuration(eta).c_str());
  return buf;
}

void Progress::Tick() {
  ++done_;
  if (!active_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const double now = timer_.ElapsedSeconds();
  if (last_print_s_ < 0 || now - last_print_s_ >= 0.25) {
    last_print_s_ = now;
    Print(false);
  }
}

void Progress::Print(bool final) {
  std::fprintf(stderr, "\r%s\033[K%s", Line().c_str(), final ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace jvl
