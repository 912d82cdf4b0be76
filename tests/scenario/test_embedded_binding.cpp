// Particles embedded in another deformable body's elements (components/deformable.h
// EmbeddedBinding, systems/embedded_binding.h; Sifakis et al. 2007): on embedded_bar.json (a soft
// bar with one end embedded in a block, thrown spinning without gravity) the embedded particles sit
// exactly at their elements' barycentric interpolation after every step, the mass is conserved,
// linear momentum is kept to round-off, and with torque-free (spring) dampers angular momentum too;
// bad "embed" entries are refused with their JSON path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "components/deformable.h"
#include "scenarios/checkpoint.h"
#include "scenarios/simulation.h"
#include "support/scenes.h"
#include "systems/embedded_binding.h"

using namespace monolith;
using test::builtins;
using test::diagnostic;
using test::kScenes;

namespace {

// The largest distance between an embedded particle and its element's interpolation, and the
// same for velocities.
std::pair<double, double> followError(World<3>& w) {
  double dx = 0, dv = 0;
  w.each<EmbeddedBinding<3>, Particles<3>>([&](Entity, EmbeddedBinding<3>& b, Particles<3>& p) {
    std::vector<double> x(p.x.size(), 0.0), v(p.v.size(), 0.0);
    forEachHostWeight<3>(w, b, [&](Entity host, int j, double wt, int i) {
      const Particles<3>& h = *w.get<Particles<3>>(host);
      for (int a = 0; a < 3; ++a) {
        x[3 * i + a] += wt * h.x[3 * j + a];
        v[3 * i + a] += wt * h.v[3 * j + a];
      }
    });
    for (int i : b.particle) {
      dx = std::max(dx, (Eigen::Vector3d(&x[3 * i]) - Eigen::Vector3d(&p.x[3 * i])).norm());
      dv = std::max(dv, (Eigen::Vector3d(&v[3 * i]) - Eigen::Vector3d(&p.v[3 * i])).norm());
    }
  });
  return {dx, dv};
}

double totalMass(World<3>& w) {
  double m = 0;
  w.each<Particles<3>>([&](Entity, Particles<3>& p) {
    for (int i = 0; i < p.count(); ++i)
      if (p.fixed[i] != 3) m += p.m[i];
  });
  return m;
}

}  // namespace

TEST(EmbeddedBinding, EmbeddedParticlesFollowTheirElementsAndMomentumIsKept) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "embedded_bar.json", {{"time.end", "0.25"}}), registry);
  const EmbeddedBinding<3>& b = *sim.world().get<EmbeddedBinding<3>>(*sim.world().find("bar"));
  // Block 0.2^3 m at 1000 kg/m^3, bar 0.4 x 0.05 x 0.05 m at 500 kg/m^3: 8 + 0.5 kg.
  EXPECT_NEAR(totalMass(sim.world()), 8.5, 1e-12);
  EXPECT_GT(b.particle.size(), 10u);
  double embeddedMass = 0;  // now the block's, which moves at 1 m/s along x
  const Particles<3>& bar = *sim.world().get<Particles<3>>(*sim.world().find("bar"));
  for (int i : b.particle) embeddedMass += bar.m[i];
  double p0x = 0, p0y = 0, worstX = 0, worstV = 0, maxDrift = 0, elastic = 0;
  while (!sim.finished()) {
    const auto& m = sim.step();
    if (sim.stepsDone() == 1) {
      p0x = diagnostic(m, "linear_momentum_x");
      p0y = diagnostic(m, "linear_momentum_y");
    }
    maxDrift = std::max({maxDrift, std::abs(diagnostic(m, "linear_momentum_x") - p0x),
                         std::abs(diagnostic(m, "linear_momentum_y") - p0y)});
    elastic = std::max(elastic, diagnostic(m, "deformable_elastic_energy"));
    const auto [dx, dv] = followError(sim.world());
    worstX = std::max(worstX, dx);
    worstV = std::max(worstV, dv);
  }
  std::printf("embedded bar: %zu embedded particles, %ld steps; follow error x %.3g m, v %.3g m/s; momentum (%.6g, %.6g), "
              "largest change %.3g; largest elastic energy %.4g J\n",
              b.particle.size(), sim.stepsDone(), worstX, worstV, p0x, p0y, maxDrift, elastic);
  EXPECT_EQ(worstX, 0.0);  // the same sum the follow system forms
  EXPECT_EQ(worstV, 0.0);
  EXPECT_NEAR(p0x, 8.0 + embeddedMass, 1e-9);  // the embedded particles start with the block's velocity
  EXPECT_LT(maxDrift, 1e-12 * std::hypot(p0x, p0y));
  EXPECT_GT(elastic, 1e-3);  // the bar is dragged and bends: the binding carries force
  EXPECT_NEAR(totalMass(sim.world()), 8.5, 1e-12);
}

// With spring dampers (forces along edges, torque-free) the forces handed to the host elements
// keep angular momentum too (with corotated Rayleigh damping it drifts: that damping's own torque
// on deformed elements, see docs/benchmarks_deformables.md).
TEST(EmbeddedBinding, AngularMomentumKeptWithTorqueFreeDampers) {
  const Registry registry = builtins();
  const std::vector<Override> springs = {{"time.end", "0.25"},
                               {"entities.bar.deformable.rayleigh_beta", "0"},
                               {"entities.block.deformable.rayleigh_beta", "0"},
                               {"entities.bar.deformable.model", "\"springs\""},
                               {"entities.block.deformable.model", "\"springs\""},
                               {"entities.bar.deformable.overdamping", "0.3"},
                               {"entities.block.deformable.overdamping", "0.3"}};
  Simulation<3> sim(loadScene(kScenes + "embedded_bar.json", springs), registry, 1);
  Simulation<3> two(loadScene(kScenes + "embedded_bar.json", springs), registry, 2);
  double L0 = 0, e0 = 0, drift = 0, e1 = 0;
  while (!sim.finished()) {
    const auto& m = sim.step();
    two.step();
    ASSERT_EQ(stateHash(sim.world()), stateHash(two.world())) << "step " << sim.stepsDone();
    if (sim.stepsDone() == 1) {
      L0 = diagnostic(m, "angular_momentum_z");
      e0 = diagnostic(m, "total_energy");
    }
    drift = std::max(drift, std::abs(diagnostic(m, "angular_momentum_z") - L0));
    e1 = diagnostic(m, "total_energy");
  }
  std::printf("embedded bar, spring dampers: angular momentum %.8g, largest change %.3g; energy %.5g -> %.5g J\n", L0, drift,
              e0, e1);
  EXPECT_LT(drift, 1e-12 * std::abs(L0));
  EXPECT_LT(e1, e0 * 0.999);  // the dampers work
}

TEST(EmbeddedBinding, BadEntriesNameTheirPath) {
  const Registry registry = builtins();
  auto message = [&](const std::vector<Override>& o) {
    try {
      Simulation<3> sim(loadScene(kScenes + "embedded_bar.json", o), registry);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string missing = message({{"entities.bar.deformable.embed.0.body", "\"nothing\""}});
  EXPECT_NE(missing.find("entities[1].deformable.embed[0].body"), std::string::npos) << missing;
  EXPECT_NE(missing.find("nothing"), std::string::npos) << missing;
  // The box reaches past the block (half extent 0.1): the bar's particles out there lie in no element.
  const std::string outside = message({{"entities.bar.deformable.embed.0.max", "[0.2, 1, 1]"}});
  EXPECT_NE(outside.find("entities[1].deformable.embed[0]"), std::string::npos) << outside;
  EXPECT_NE(outside.find("outside every element"), std::string::npos) << outside;
  const std::string empty = message({{"entities.bar.deformable.embed.0.min", "[5, 5, 5]"}, {"entities.bar.deformable.embed.0.max", "[6, 6, 6]"}});
  EXPECT_NE(empty.find("containing none"), std::string::npos) << empty;
}
