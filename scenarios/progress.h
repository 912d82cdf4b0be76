#pragma once
// Progress on stderr: a redrawn bar with ETA on a terminal, plain lines (every 10 %) otherwise.
#include <chrono>
#include <string>

namespace monolith {

class Progress {
 public:
  Progress(long total, long first, bool enabled);
  void update(long done);
  void finish(const std::string& status);

 private:
  long total_, first_;
  bool enabled_, tty_;
  int lastDecile_ = -1;
  std::chrono::steady_clock::time_point start_, lastDraw_;
};

}  // namespace monolith
