#include "scenarios/progress.h"

#include <unistd.h>

#include <cstdio>

namespace monolith {

namespace {
std::string formatSeconds(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
  return buf;
}
}  // namespace

Progress::Progress(long total, long first, bool enabled)
    : total_(total), first_(first), enabled_(enabled && total > 0), tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()), lastDraw_(start_) {}

void Progress::update(long done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double fraction = double(done) / double(total_);
  const long doneHere = done - first_;
  const double eta = doneHere > 0 ? elapsed / doneHere * (total_ - done) : 0.0;
  if (tty_) {
    if (done < total_ && std::chrono::duration<double>(now - lastDraw_).count() < 0.1) return;
    lastDraw_ = now;
    const int width = 30, filled = int(fraction * width);
    std::fprintf(stderr, "\r[%.*s%.*s] %3d%%  step %ld/%ld  elapsed %s  ETA %s   ", filled,
                 "##############################", width - filled, "..............................",
                 int(fraction * 100), done, total_, formatSeconds(elapsed).c_str(), formatSeconds(eta).c_str());
    std::fflush(stderr);
  } else {
    const int decile = int(fraction * 10);
    if (decile == lastDecile_) return;
    lastDecile_ = decile;
    std::fprintf(stderr, "progress: %3d%% step %ld/%ld elapsed %s eta %s\n", decile * 10, done, total_,
                 formatSeconds(elapsed).c_str(), formatSeconds(eta).c_str());
  }
}

void Progress::finish(const std::string& status) {
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "%s%s in %s\n", tty_ ? "\n" : "", status.c_str(), formatSeconds(elapsed).c_str());
}

}  // namespace monolith
