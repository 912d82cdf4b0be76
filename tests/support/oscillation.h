#pragma once
// Period and extremes of a sampled periodic signal (lift on a cylinder behind which vortices
// shed): the period is the mean spacing of the upward crossings of the signal's mean, each
// crossing located by linear interpolation between samples, so it is accurate to O(dt^2) for a
// smooth signal rather than to one sample.
#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

namespace monolith::test {

struct Oscillation {
  int crossings = 0;      // upward crossings used (periods = crossings - 1)
  double period = 0;      // 0 if fewer than two crossings
  double mean = 0, max = 0, min = 0;
  double frequency() const { return period > 0 ? 1.0 / period : 0.0; }
};

// Samples (t[i], y[i]) with t increasing; only samples with t >= from are analysed.
inline Oscillation analyseOscillation(const std::vector<double>& t, const std::vector<double>& y, double from) {
  Oscillation o;
  std::size_t first = 0;
  while (first < t.size() && t[first] < from) ++first;
  if (t.size() - first < 3) return o;
  double sum = 0;
  o.max = -std::numeric_limits<double>::infinity();
  o.min = std::numeric_limits<double>::infinity();
  for (std::size_t i = first; i < t.size(); ++i) {
    sum += y[i];
    o.max = std::max(o.max, y[i]);
    o.min = std::min(o.min, y[i]);
  }
  o.mean = sum / double(t.size() - first);
  // Schmitt trigger: a crossing counts only after the signal has been below the mean by a
  // quarter of its peak-to-peak range, so small high-frequency noise (the staircase boundary's
  // pressure jitter) does not add crossings.
  const double band = 0.25 * (o.max - o.min);
  bool armed = false;
  double firstCrossing = 0, lastCrossing = 0;
  for (std::size_t i = first + 1; i < t.size(); ++i) {
    const double a = y[i - 1] - o.mean, b = y[i] - o.mean;
    if (y[i - 1] < o.mean - band) armed = true;
    if (armed && a < 0 && b >= 0) {
      armed = false;
      const double crossing = t[i - 1] + (t[i] - t[i - 1]) * (-a) / (b - a);
      if (o.crossings == 0) firstCrossing = crossing;
      lastCrossing = crossing;
      ++o.crossings;
    }
  }
  if (o.crossings >= 2) o.period = (lastCrossing - firstCrossing) / (o.crossings - 1);
  return o;
}

}  // namespace monolith::test
