// Progress of a frame loop on stderr: "name k/N  12.3 frames/s  ETA 0:42".
// Silent when stderr is not a terminal or when disabled; safe to call from several threads.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "core/timer.h"

namespace jvl {

class Progress {
 public:
  // enabled=false silences it; otherwise it prints only if stderr is a terminal.
  Progress(std::string name, int64_t total, bool enabled = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Marks one more item done.
  void Tick();
  // The line that would be printed now (for tests and logs).
  std::string Line() const;
  int64_t done() const { return done_.load(); }
  bool active() const { return active_; }

 private:
  void Print(bool final);

  std::string name_;
  int64_t total_;
  bool active_;
  std::atomic<int64_t> done_{0};
  Timer timer_;
  double last_print_s_ = -1.0;
  std::mutex mutex_;
};

// "1:02:03" or "2:03".
std::string FormatDuration(double seconds);

}  // namespace jvl
