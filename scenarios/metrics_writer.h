#pragma once
// metrics.csv: one row per step. The schema is fixed by the first row: the base columns
// below (always present, 0 when a scene has nothing they measure), then every other
// diagnostic in name order, then one wall-time column per scheduled stage.
#include <array>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "ecs/stage.h"

namespace monolith {

inline const std::vector<std::string> kBaseMetricColumns = {
    "kinetic_energy",    "potential_energy",   "total_energy",       "linear_momentum_x",
    "linear_momentum_y", "linear_momentum_z",  "angular_momentum_x", "angular_momentum_y",
    "angular_momentum_z"};

class MetricsWriter {
 public:
  // `keepThroughStep` >= 0 keeps an existing file's rows up to that step (resume); else truncates.
  MetricsWriter(const std::string& path, long keepThroughStep);
  void row(long step, double time, double dt, const std::map<std::string, double>& diagnostics,
           const std::vector<Stage>& stages, const std::array<double, static_cast<int>(Stage::Count)>& stageSeconds,
           double wallSeconds);

 private:
  std::string path_;
  std::ofstream out_;
  std::vector<std::string> extra_;
  std::vector<Stage> stages_;
  bool headerWritten_ = false;
};

}  // namespace monolith
