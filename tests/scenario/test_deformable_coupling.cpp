// Deformable solids at frame-rate steps with elastic substepping, and two-way coupled scenes of
// the thesis's Ch. 4 (systems/deformable_dynamics.h, solvers/deformable/stable_step.h): energy
// never grows past its initial value, momentum is conserved through rigid/deformable impacts,
// Coulomb friction on an incline, a stiff material at a large frame step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "components/deformable.h"
#include "components/rigid_body.h"
#include "scenarios/simulation.h"
#include "support/scenes.h"

using namespace monolith;
using test::builtins;
using test::kScenes;

namespace {

using Overrides = std::vector<std::pair<std::string, std::string>>;

double value(const std::map<std::string, double>& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? 0.0 : it->second;
}

struct EnergyRun {
  double initial = 0, largest = 0, last = 0;
  long steps = 0;
  double frames = 0;
};

EnergyRun runForEnergy(const std::string& scene, const Overrides& overrides) {
  const Registry registry = builtins();
  const SceneSpec spec = loadScene(kScenes + scene, overrides);
  Simulation<3> sim(spec, registry);
  EnergyRun r;
  bool first = true;
  while (!sim.finished()) {
    const auto& m = sim.step();
    const double E = value(m, "total_energy");
    if (first) r.initial = r.largest = E;  // after the first substep (gravity: E0 up to O(dt^2))
    first = false;
    r.largest = std::max(r.largest, E);
    r.last = E;
  }
  r.steps = sim.stepsDone();
  r.frames = spec.endTime * 120;
  return r;
}

}  // namespace

// An elastic ball (neo-Hookean, E = 2e4 Pa) dropped 0.5 m onto the ground at frames of 1/120 s,
// each split into substeps by the elastic CFL condition (cfl 0.5): through the impact and the
// rebound the total energy never exceeds its initial value by more than 0.1 %, with and without
// Rayleigh damping.
TEST(DeformableCoupling, DropSphereElasticEnergyBoundedAtFrameRate) {
  for (const char* beta : {"0.01", "0"}) {
    const EnergyRun r = runForEnergy("drop_sphere_elastic.json",
                                     {{"time.end", "0.6"}, {"entities.ball.deformable.rayleigh_beta", beta}});
    std::printf("drop_sphere_elastic beta %s: E0 %.6f, max %.6f (%.2e relative), end %.4f, %.1f substeps per frame\n",
                beta, r.initial, r.largest, (r.largest - r.initial) / r.initial, r.last, r.steps / r.frames);
    EXPECT_LE(r.largest, r.initial * (1 + 1e-3)) << "beta " << beta;
    EXPECT_LT(r.last, r.initial) << "the impact is inelastic";
    EXPECT_GT(r.steps / r.frames, 2.0);  // the frame is substepped
  }
}
