#pragma once
// Probes and profiles of a fluid run: probes.csv gets one row per step with the velocity and
// pressure at each probe point; profiles/<name>_<step>.csv samples a line at every frame
// (e.g. the cavity centre lines compared with Ghia et al.).
#include <fstream>
#include <string>

#include "ecs/world.h"
#include "scenarios/scene.h"

namespace monolith {

template <int d>
class FluidProbeWriter {
 public:
  // Checks that every point lies in the grid (SceneError at the spec's JSON path if not).
  // keepThroughStep >= 0: resume, keep the existing rows up to that step.
  FluidProbeWriter(const SceneSpec& scene, const World<d>& world, const std::string& outDir, long keepThroughStep);
  void afterStep(const World<d>& world, long step, double time);
  void frame(const World<d>& world, long step);
  bool active() const { return active_; }

 private:
  const SceneSpec& scene_;
  std::string outDir_;
  std::ofstream probes_;
  bool active_ = false;
};

}  // namespace monolith
