#include "scenarios/metrics_writer.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace monolith {

namespace {
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
}  // namespace

MetricsWriter::MetricsWriter(const std::string& path, long keepThroughStep) : path_(path) {
  std::vector<std::string> kept;
  if (keepThroughStep >= 0) {
    std::ifstream in(path);
    std::string line;
    if (std::getline(in, line)) {
      kept.push_back(line);
      while (std::getline(in, line)) {
        const long step = std::stol(line.substr(0, line.find(',')));
        if (step <= keepThroughStep) kept.push_back(line);
      }
    }
  }
  out_.open(path, std::ios::trunc);
  if (!out_) throw std::runtime_error("cannot write '" + path + "'");
  for (const auto& l : kept) out_ << l << '\n';
  headerWritten_ = !kept.empty();
  // On resume the header is kept; the schema is the same because the same scene runs.
}

void MetricsWriter::row(long step, double time, double dt, const std::map<std::string, double>& diagnostics,
                        const std::vector<Stage>& stages,
                        const std::array<double, static_cast<int>(Stage::Count)>& stageSeconds, double wallSeconds) {
  if (extra_.empty() && stages_.empty()) {
    for (const auto& [key, _] : diagnostics)
      if (std::find(kBaseMetricColumns.begin(), kBaseMetricColumns.end(), key) == kBaseMetricColumns.end())
        extra_.push_back(key);
    stages_ = stages;
    if (!headerWritten_) {
      out_ << "step,time,dt";
      for (const auto& c : kBaseMetricColumns) out_ << ',' << c;
      out_ << ",wall_seconds";
      for (const auto& c : extra_) out_ << ',' << c;
      for (Stage s : stages_) out_ << ",stage_" << stageName(s) << "_seconds";
      out_ << '\n';
      headerWritten_ = true;
    }
  }
  std::ostringstream line;
  line << step << ',' << num(time) << ',' << num(dt);
  auto value = [&](const std::string& key) {
    auto it = diagnostics.find(key);
    return it == diagnostics.end() ? 0.0 : it->second;
  };
  for (const auto& c : kBaseMetricColumns) line << ',' << num(value(c));
  line << ',' << num(wallSeconds);
  for (const auto& c : extra_) line << ',' << num(value(c));
  for (Stage s : stages_) line << ',' << num(stageSeconds[static_cast<int>(s)]);
  out_ << line.str() << '\n';
  out_.flush();
}

}  // namespace monolith
