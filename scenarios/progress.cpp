#include "scenarios/progress.h"

#include <unistd.h>

#include <algorithm>
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

Progress::Progress(double end, double start, long totalSteps, bool enabled)
    : end_(end), start_(start), totalSteps_(totalSteps), enabled_(enabled && end > 0), tty_(::isatty(STDERR_FILENO) != 0),
      started_(std::chrono::steady_clock::now()), lastDraw_(started_) {}

void Progress::update(double time, long step) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - started_).count();
  const double fraction = std::min(1.0, time / end_);
  const double doneHere = time - start_;
  const double eta = doneHere > 0 ? elapsed / doneHere * (end_ - time) : 0.0;
  const bool last = fraction >= 1.0;
  char stepText[48];
  if (totalSteps_ > 0) std::snprintf(stepText, sizeof stepText, "step %ld/%ld", step, totalSteps_);
  else std::snprintf(stepText, sizeof stepText, "step %ld", step);
  if (tty_) {
    if (!last && std::chrono::duration<double>(now - lastDraw_).count() < 0.1) return;
    lastDraw_ = now;
    const int width = 30, filled = int(fraction * width);
    std::fprintf(stderr, "\r[%.*s%.*s] %3d%%  %s  t %.4g/%.4g  elapsed %s  ETA %s   ", filled,
                 "##############################", width - filled, "..............................",
                 int(fraction * 100), stepText, time, end_, formatSeconds(elapsed).c_str(), formatSeconds(eta).c_str());
    std::fflush(stderr);
  } else {
    const int decile = int(fraction * 10);
    if (decile == lastDecile_) return;
    lastDecile_ = decile;
    std::fprintf(stderr, "progress: %3d%% %s t %.6g/%.6g elapsed %s eta %s\n", decile * 10, stepText, time, end_,
                 formatSeconds(elapsed).c_str(), formatSeconds(eta).c_str());
  }
}

void Progress::finish(const std::string& status) {
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  std::fprintf(stderr, "%s%s in %s\n", tty_ ? "\n" : "", status.c_str(), formatSeconds(elapsed).c_str());
}

}  // namespace monolith
