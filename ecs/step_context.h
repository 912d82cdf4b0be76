#pragma once
// What a system gets besides the world: the step's time levels, the solver settings of the
// scene and a sink for per-step diagnostics (columns of metrics.csv).
#include <map>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

namespace monolith {

// Thread-safe, ordered: systems of one stage may run concurrently and report at once;
// the ordered map keeps the metrics columns in a stable order.
class DiagnosticsSink {
 public:
  void set(const std::string& key, double value) {
    std::lock_guard<std::mutex> lock(mutex_);
    values_[key] = value;
  }
  // Keeps the maximum across reports (e.g. worst energy error over bodies).
  void max(const std::string& key, double value) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto [it, inserted] = values_.emplace(key, value);
    if (!inserted && value > it->second) it->second = value;
  }
  void add(const std::string& key, double value) {
    std::lock_guard<std::mutex> lock(mutex_);
    values_[key] += value;
  }
  const std::map<std::string, double>& values() const { return values_; }
  void clear() { values_.clear(); }

 private:
  std::mutex mutex_;
  std::map<std::string, double> values_;
};

struct StepContext {
  double dt = 0;
  double time = 0;  // t^n: the time at the start of the step
  long step = 0;    // index n of the step being taken (0-based)
  DiagnosticsSink diagnostics;
};

}  // namespace monolith
