// Landing across a gap narrower than one step's fall (ContactSettings::closeGaps). At dt = 1/30
// a body at rest falls g dt^2 / 2 = 5.45 mm in its first step, so a support closer than that is
// met at the candidate poses before the body reaches it. The short schedule's one fully
// inelastic contact pass used to take every such point as touching (v_n >= 0) and stop the body
// where it was, in the air, for good; with gaps closed (v_n >= -gap/dt) it lands.
//
// "Landed" means the gap left is within the push-out tolerance (1e-5 m) of zero: push-out leaves
// overlaps below it alone, so that is how close the code itself puts resting bodies, and it is
// 60-450 times smaller than the gaps dropped across (0.6-4.5 mm). The stop in the air the tests
// guard against leaves the whole gap.
#include <gtest/gtest.h>

#include "support/scenes.h"
#include "support/unit_cube_obj.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>
#include <vector>
#include <string>

#include "components/rigid_body.h"
#include "scenarios/simulation.h"

using namespace monolith;

namespace {
using test::bodyNamed;
using test::builtins;

using Overrides = std::vector<std::pair<std::string, std::string>>;
constexpr double kLanded = 1e-5;  // ContactSettings::pushOutTolerance


// Runs the scene to its end and returns the y of `name` (the largest total-energy rise over the
// start, relative to the start's |E|, in `rise`).
template <int d>
double finalY(const std::string& text, const Overrides& overrides, const std::string& name, double* rise = nullptr) {
  const Registry registry = builtins();
  Simulation<d> sim(parseScene(text, "gap.json", overrides), registry);
  double first = 0, worst = 0;
  bool started = false;
  while (!sim.finished()) {
    const auto& diag = sim.step();
    const double e = diag.at("total_energy");
    if (!started) first = e, started = true;
    worst = std::max(worst, e - first);
  }
  if (rise) *rise = worst / std::max(std::abs(first), 1e-12);
  return bodyNamed<d>(sim, name).x.y();
}

std::string boxOnShelf(double gap, bool kinematicShelf) {
  // A 0.4 m box at rest with its bottom `gap` above a 4 cm shelf's top (y = 2.02), dt = 1/30.
  const std::string shelfBody = kinematicShelf ? R"("rigid_body": {"mass": 100, "position": [0, 2, 0]},
         "kinematic": {"schedule": [{"velocity": [0, 0, 0]}]},)"
                                               : R"("rigid_body": {"static": true, "position": [0, 2, 0]},)";
  return R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 1.0}, "gravity": [0, -9.81, 0],
      "entities": [
        {"name": "shelf", "shape": {"type": "box", "half_extents": [1, 0.02, 1]}, )" +
         shelfBody + R"( "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "box", "shape": {"type": "box", "half_extents": [0.2, 0.2, 0.2]},
         "rigid_body": {"mass": 1, "position": [0.1, )" +
         std::to_string(2.22 + gap) + R"(, 0.05]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
}
}  // namespace

TEST(ContactGaps, ABoxDroppedAFewMillimetresOntoAShelfLandsOnTheShortSchedule) {
  for (const bool kinematic : {false, true}) {
    for (double gap : {0.6e-3, 2e-3, 3e-3, 4.5e-3}) {
      const std::string scene = boxOnShelf(gap, kinematic);
      double rise = 0;
      const double landed = finalY<3>(scene, {{"solvers.contact.schedule", "short"}}, "box", &rise) - 2.22;
      const double hovered =
          finalY<3>(scene, {{"solvers.contact.schedule", "short"}, {"solvers.contact.close_gaps", "false"}}, "box") -
          2.22;
      std::printf("%s shelf, dropped %.1f mm: rests %.2e m above it (%.2e without closing gaps), energy rise %.1e\n",
                  kinematic ? "kinematic" : "static", gap * 1e3, landed, hovered, rise);
      EXPECT_NEAR(landed, 0.0, kLanded) << (kinematic ? "kinematic" : "static") << " shelf, gap " << gap;
      EXPECT_GT(hovered, 0.5 * gap) << "without closing gaps the box stops in the air";
      EXPECT_LE(rise, 1e-9);
    }
  }
}

TEST(ContactGaps, TheThesisScheduleClosesSuchGapsByItsSweepsAndTheDefaultByClosingThem) {
  // The thesis's ten epsilon-ramped sweeps close such a gap approximately (to 0.1 mm), without
  // closeGaps: each removes only part of the approach, the next sees what is left of the gap.
  // The default (the short schedule) closes it by v_n >= -gap/dt.
  const std::string scene = boxOnShelf(3e-3, false);
  EXPECT_NEAR(finalY<3>(scene, {}, "box") - 2.22, 0.0, 2e-4);
  EXPECT_NEAR(finalY<3>(scene, {{"solvers.contact.schedule", "thesis"}}, "box") - 2.22, 0.0, 2e-4);
}

TEST(ContactGaps, ADiskDroppedAFewMillimetresOntoABarLandsOnTheShortSchedule) {
  for (double gap : {1e-3, 3e-3}) {
    const std::string scene = R"({"dimension": 2, "time": {"dt": 0.03333333333333333, "end": 1.0}, "gravity": [0, -9.81],
      "entities": [
        {"name": "bar", "shape": {"type": "box", "half_extents": [1.0, 0.01]},
         "rigid_body": {"static": true, "position": [0, 2]}, "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "disk", "shape": {"type": "disk", "radius": 0.1},
         "rigid_body": {"mass": 1, "position": [0.05, )" + std::to_string(2.11 + gap) +
                              R"(]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
    EXPECT_NEAR(finalY<2>(scene, {{"solvers.contact.schedule", "short"}}, "disk") - 2.11, 0.0, kLanded) << gap;
    const Overrides open = {{"solvers.contact.schedule", "short"}, {"solvers.contact.close_gaps", "false"}};
    EXPECT_GT(finalY<2>(scene, open, "disk") - 2.11, 0.5 * gap) << "without closing gaps the disk stops in the air";
  }
}

TEST(ContactGaps, ABoxDroppedAFewMillimetresOntoADynamicMeshCubeLandsOnTheShortSchedule) {
  // A unit cube read from an OBJ file resting on the ground, a small box 2 mm above it at dt =
  // 1/30 (the mesh's triangles against the box: FCL per triangle plus the feature points).
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "monolith_contact_gaps_mesh";
  std::filesystem::create_directories(dir);
  test::writeUnitCubeObj(dir / "cube.obj");
  const std::string scene = R"({"dimension": 3, "time": {"dt": 0.03333333333333333, "end": 1.5}, "gravity": [0, -9.81, 0],
      "entities": [
        {"name": "ground", "shape": {"type": "plane", "normal": [0, 1, 0]}, "rigid_body": {"static": true},
         "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "mesh_cube", "shape": {"type": "mesh", "file": ")" +
                            (dir / "cube.obj").string() + R"("},
         "rigid_body": {"mass": 1, "inertia": [0.16666666666666666, 0.16666666666666666, 0.16666666666666666],
                        "position": [0, 0.5, 0]}, "collider": {"restitution": 0, "friction": 0.5}},
        {"name": "box", "shape": {"type": "box", "half_extents": [0.3, 0.2, 0.3]},
         "rigid_body": {"mass": 1, "position": [0.1, 1.202, 0.05]}, "collider": {"restitution": 0, "friction": 0.5}}]})";
  const Registry registry = builtins();
  Simulation<3> sim(parseScene(scene, "mesh_gap.json", {{"solvers.contact.schedule", "short"}}), registry);
  while (!sim.finished()) sim.step();
  const double gap = (bodyNamed<3>(sim, "box").x.y() - 0.2) - (bodyNamed<3>(sim, "mesh_cube").x.y() + 0.5);
  std::printf("box on the mesh cube: gap %.2e m, cube at %.6f\n", gap, bodyNamed<3>(sim, "mesh_cube").x.y());
  EXPECT_NEAR(gap, 0.0, kLanded);
  EXPECT_NEAR(bodyNamed<3>(sim, "mesh_cube").x.y(), 0.5, kLanded);
}
