// Wall-clock timing and peak resident memory of the process.
#pragma once

#include <chrono>
#include <cstdint>

namespace jvl {

class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  void Reset() { start_ = std::chrono::steady_clock::now(); }
  double ElapsedSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  double ElapsedMs() const { return 1e3 * ElapsedSeconds(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Peak resident set size of this process in bytes (VmHWM), 0 if unavailable.
int64_t PeakMemoryBytes();

}  // namespace jvl
