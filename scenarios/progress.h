#pragma once
// Progress on stderr: a redrawn bar with ETA on a terminal, plain lines (every 10 %) otherwise.
#include <chrono>
#include <string>

namespace monolith {

class Progress {
 public:
  // Progress in simulated time from `start` to `end`; totalSteps > 0 when the count is known.
  Progress(double end, double start, long totalSteps, bool enabled);
  void update(double time, long step);
  void finish(const std::string& status);

 private:
  double end_, start_;
  long totalSteps_;
  bool enabled_, tty_;
  int lastDecile_ = -1;
  std::chrono::steady_clock::time_point started_, lastDraw_;
};

}  // namespace monolith
