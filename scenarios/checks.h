#pragma once
// Checks: what a scene's result should be ("checks": [...] at the top level of a scene). Each
// check observes one quantity during the run -- a diagnostic of metrics.csv, a rigid body's
// field, the fluid at a probe point, or the fluid along a line (a profile) -- reduces it to a
// value (final, at a time, max, min, largest change from the start) and compares it with a
// reference: a number, a vector, or a named analytic or tabulated reference (references.h).
// `monolith run` writes value, error and pass into summary.json and prints them; with --check a
// failed check is exit code 5. docs/tools.md lists every key.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <map>

#include "ecs/config.h"
#include "ecs/world.h"

namespace monolith {

struct CheckSpec {
  std::string name, kind;      // kind: diagnostic | body | probe | profile
  std::string target;          // diagnostic name, entity name; "" for probes and profiles
  std::string field;           // body: position|velocity|angular_momentum|displacement|orientation; probe/profile: u|v|w|p
  int axis = -1;               // component of a vector field (else its length, or `direction`)
  std::vector<double> direction;
  std::vector<double> position, from, to;  // probe point; profile line
  int points = 0;              // profile samples (analytic references); tables use their own points
  std::string statistic = "final";  // final | max | min | max_change | max_relative_change
  double at = -1;              // >= 0: the value at this time instead of the end
  double after = 0;            // max/min/changes only over t >= after
  double scale = 1;            // the observed value is multiplied by this (e.g. force -> coefficient)
  std::vector<double> reference;    // numbers (one, or one per component)
  std::string referenceName;        // a named reference instead (references.h)
  Json referenceParameters;         // its parameters
  std::string norm = "absolute";    // absolute | relative | max | rms (profiles: max, rms, relative)
  double tolerance = 0;
  std::string path;            // JSON path, for messages
};

struct CheckResult {
  std::string name;
  double value = 0, reference = 0, error = 0, tolerance = 0;
  bool pass = false;
  std::string note;  // e.g. why no value could be taken
};

// Parses and validates the scene's "checks" (SceneError with the JSON path on a mistake).
std::vector<CheckSpec> parseChecks(const Json& scene, const std::string& file, int dimension);

// What a check has seen so far (CheckEvaluator).
struct CheckState {
  bool started = false, haveAt = false, haveExtreme = false, haveLast = false;
  Eigen::VectorXd initial;
  double extreme = 0, change = 0, atValue = 0, last = 0;
  Eigen::Vector4d q0 = Eigen::Vector4d::Zero();  // the body's start orientation (w, x, y, z)
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();
  Eigen::Vector3d L = Eigen::Vector3d::Zero();
};

// Observes the checks' quantities step by step and evaluates them at the end.
template <int d>
class CheckEvaluator {
 public:
  // Fails (SceneError) when a check names an entity, diagnostic source or point the world lacks.
  CheckEvaluator(std::vector<CheckSpec> checks, const World<d>& world, const std::string& file, double startTime);
  void observe(const World<d>& world, const std::map<std::string, double>& diagnostics, double time);
  std::vector<CheckResult> finish(const World<d>& world, double time);
  bool empty() const { return checks_.empty(); }

 private:
  using State = CheckState;
  Eigen::VectorXd quantity(const CheckSpec& c, const World<d>& world, const std::map<std::string, double>& diag,
                           bool& available) const;
  std::vector<CheckSpec> checks_;
  std::vector<State> states_;
  std::string file_;
  double startTime_;
};

// Writes the results as a JSON array (summary.json "checks") and as the lines printed at the end.
Json checksToJson(const std::vector<CheckResult>& results);
std::string formatChecks(const std::vector<CheckResult>& results);

}  // namespace monolith
