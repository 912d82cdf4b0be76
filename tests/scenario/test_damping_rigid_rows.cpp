// The rigid unknowns' own constraints in the damping solves of Steps I and V (systems/
// particle_contact.h `DampingSolveContacts::rigidRows`, solvers/deformable/coupled_damping.h;
// thesis Sec. 4.7.1, 4.7.3): a box resting on a box brings the upper box into the solve, its
// contact rows measure the relative normal velocity at the points (zero for any common rigid
// motion, minus the approach speed when the upper box comes down), a joint's rows vanish for a
// common rigid motion and for the turn it allows, in 3-D and 2-D; and on the light box under a
// heavy block the block settles faster with the box held by the ground inside the solve.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenarios/scene.h"
#include "support/scenes.h"
#include "systems/particle_contact.h"

using namespace monolith;
using test::builtins;
using test::kScenes;

namespace {

const char* kStack3 = R"({
  "dimension": 3,
  "time": { "dt": 0.001, "end": 0.01 },
  "gravity": [0, -9.81, 0],
  "entities": [
    { "name": "ground", "shape": { "type": "plane", "normal": [0, 1, 0] }, "rigid_body": { "static": true },
      "collider": { "restitution": 0, "friction": 0.5 } },
    { "name": "lower", "shape": { "type": "box", "half_extents": [0.1, 0.05, 0.1] },
      "rigid_body": { "mass": 2, "position": [0, 0.155, 0] }, "collider": { "restitution": 0, "friction": 0.5 } },
    { "name": "upper", "shape": { "type": "box", "half_extents": [0.1, 0.05, 0.1] },
      "rigid_body": { "mass": 20, "position": [0.02, 0.2555, 0] }, "collider": { "restitution": 0, "friction": 0.5 } }
    JOINT
  ]
})";

const char* kJoint3 = R"(,
    { "name": "hinge", "joint": { "type": "revolute", "parent": "lower", "child": "upper",
      "anchor": [0.12, 0.205, 0], "axis": [0, 0, 1] } })";

const char* kPair2 = R"({
  "dimension": 2,
  "time": { "dt": 0.001, "end": 0.01 },
  "gravity": [0, -9.81],
  "entities": [
    { "name": "lower", "shape": { "type": "box", "half_extents": [0.1, 0.05] },
      "rigid_body": { "mass": 2, "position": [0, 0.5] } },
    { "name": "upper", "shape": { "type": "box", "half_extents": [0.1, 0.05] },
      "rigid_body": { "mass": 3, "position": [0.25, 0.5], "angle": 0.3 },
      "joint": { "type": "revolute", "parent": "lower", "anchor": [0.12, 0.5] } }
  ]
})";

std::string withJoint(bool joint) {
  std::string s = kStack3;
  s.replace(s.find("JOINT"), 5, joint ? kJoint3 : "");
  return s;
}

template <int d>
using Twist = solvers::deformable::DampingTwist<d>;

// The twist of body b under the common rigid motion (V, W) about the origin.
template <int d>
Twist<d> commonTwist(const RigidBody<d>& b, const Vec<d>& V, const AngularVec<d>& W) {
  Twist<d> t;
  if constexpr (d == 3) t.template head<3>() = V + W.cross(b.x);
  else t.template head<2>() = V + Vec<2>(-W(0) * b.x.y(), W(0) * b.x.x());
  t.template tail<AngularVec<d>::RowsAtCompileTime>() = W;
  return t;
}

// The row's velocity with the lower and upper boxes at these twists (a row may name them in
// either order: a joint's rows are on the child first).
template <int d>
double rowVelocity(const RigidConstraintRow<d>& r, Entity lower, const Twist<d>& lowerTwist, const Twist<d>& upperTwist) {
  const Twist<d>& a = r.a == lower ? lowerTwist : upperTwist;
  const Twist<d>& b = r.b == lower ? lowerTwist : upperTwist;
  return r.ga.dot(a) + (r.b.valid() ? r.gb.dot(b) : 0.0);
}

}  // namespace

// A box resting (0.5 mm above) on a box: the upper one joins the unknowns, and the contact rows
// (normal out of the upper box, towards the lower) read the relative normal velocity at the
// points: zero for a common rigid motion, -1 with the upper box coming down at 1 m/s. The lower
// box lies 0.105 m above the ground: no ground row.
TEST(DampingRigidRows, BoxOnBoxJoinsTheSolveAndRowsReadTheRelativeNormalVelocity) {
  const Registry registry = builtins();
  Simulation<3> sim(parseScene(withJoint(false), "stack.json"), registry);
  World<3>& world = sim.world();
  const Entity lower = *world.find("lower"), upper = *world.find("upper");
  DampingSolveContacts<3> contacts;
  std::vector<Entity> unknowns = {lower};
  const std::vector<RigidConstraintRow<3>> rows = contacts.rigidRows(world, unknowns, 1e-3, 0.0);
  ASSERT_EQ(unknowns.size(), 2u);
  EXPECT_EQ(unknowns[1], upper);
  ASSERT_GE(rows.size(), 3u);  // a face manifold (four corners of the overlap)
  const RigidBody<3>& a = *world.get<RigidBody<3>>(lower);
  const RigidBody<3>& b = *world.get<RigidBody<3>>(upper);
  double worstCommon = 0, worstApproach = 0;
  for (const RigidConstraintRow<3>& r : rows) {
    EXPECT_EQ(r.a, lower);
    EXPECT_EQ(r.b, upper);
    EXPECT_EQ(r.target, 0.0);  // at rest, Step I
    const Eigen::Vector3d V(0.3, -0.2, 0.5), W(1.0, -2.0, 0.7);
    worstCommon = std::max(worstCommon, std::abs(rowVelocity<3>(r, lower, commonTwist<3>(a, V, W), commonTwist<3>(b, V, W))));
    Twist<3> down = Twist<3>::Zero();
    down(1) = -1;
    worstApproach = std::max(worstApproach, std::abs(rowVelocity<3>(r, lower, Twist<3>::Zero(), down) + 1));
  }
  std::printf("box on box: %zu contact rows; common rigid motion %.1e, approach error %.1e\n", rows.size(),
              worstCommon, worstApproach);
  EXPECT_LT(worstCommon, 1e-12);
  EXPECT_LT(worstApproach, 1e-12);
}

// The same boxes hinged about z at (0.12, 0.205, 0): five joint rows (three linear, two angular)
// beside the contact rows; every row vanishes for a common rigid motion, the joint rows also for
// the upper box's turn about the hinge, and not all of them for a turn about x.
TEST(DampingRigidRows, JointRowsAllowTheHingeTurnOnly) {
  const Registry registry = builtins();
  Simulation<3> plain(parseScene(withJoint(false), "stack.json"), registry);
  std::vector<Entity> plainUnknowns = {*plain.world().find("lower")};
  const std::vector<RigidConstraintRow<3>> withoutJoint =
      DampingSolveContacts<3>().rigidRows(plain.world(), plainUnknowns, 1e-3, 0.0);
  Simulation<3> sim(parseScene(withJoint(true), "stack.json"), registry);
  World<3>& world = sim.world();
  const Entity lower = *world.find("lower"), upper = *world.find("upper");
  DampingSolveContacts<3> contacts;
  std::vector<Entity> unknowns = {lower};
  const std::vector<RigidConstraintRow<3>> rows = contacts.rigidRows(world, unknowns, 1e-3, 0.0);
  ASSERT_EQ(unknowns.size(), 2u);
  EXPECT_EQ(unknowns[1], upper);
  ASSERT_GT(rows.size(), withoutJoint.size());
  const RigidBody<3>& a = *world.get<RigidBody<3>>(lower);
  const RigidBody<3>& b = *world.get<RigidBody<3>>(upper);
  const Eigen::Vector3d anchor(0.12, 0.205, 0);
  double worstCommon = 0, worstHinge = 0, largestTilt = 0;
  for (const RigidConstraintRow<3>& r : rows) {
    const Eigen::Vector3d V(-0.1, 0.4, 0.2), W(0.3, 0.9, -1.1);
    worstCommon = std::max(worstCommon, std::abs(rowVelocity<3>(r, lower, commonTwist<3>(a, V, W), commonTwist<3>(b, V, W))));
  }
  // The upper box turning about an axis through the anchor.
  auto turnAbout = [&](const Eigen::Vector3d& axis) {
    Twist<3> t;
    t.head<3>() = axis.cross(b.x - anchor);
    t.tail<3>() = axis;
    return t;
  };
  // The lower box's rows: its contacts with the upper box, then its joint's; the upper box adds
  // none (its only neighbour is the lower box, already done).
  const int jointRows = static_cast<int>(rows.size() - withoutJoint.size());
  for (std::size_t k = withoutJoint.size(); k < rows.size(); ++k) {
    const RigidConstraintRow<3>& r = rows[k];
    worstHinge = std::max(worstHinge, std::abs(rowVelocity<3>(r, lower, Twist<3>::Zero(), turnAbout(Eigen::Vector3d::UnitZ()))));
    largestTilt = std::max(largestTilt, std::abs(rowVelocity<3>(r, lower, Twist<3>::Zero(), turnAbout(Eigen::Vector3d::UnitX()))));
  }
  std::printf("hinged boxes: %zu rows (%d of the joint); common motion %.1e, hinge turn %.1e, tilt %.2f\n", rows.size(),
              jointRows, worstCommon, worstHinge, largestTilt);
  EXPECT_EQ(jointRows, 5);
  EXPECT_LT(worstCommon, 1e-12);
  EXPECT_LT(worstHinge, 1e-12);
  EXPECT_GT(largestTilt, 0.5);
}

// 2-D: a pin between two boxes (no colliders): two linear rows in the plane, zero for a common
// rigid motion and for the turn about the pin, not for a slide of the upper box.
TEST(DampingRigidRows, PinRowsIn2d) {
  const Registry registry = builtins();
  Simulation<2> sim(parseScene(kPair2, "pair.json"), registry);
  World<2>& world = sim.world();
  const Entity lower = *world.find("lower"), upper = *world.find("upper");
  DampingSolveContacts<2> contacts;
  std::vector<Entity> unknowns = {lower};
  const std::vector<RigidConstraintRow<2>> rows = contacts.rigidRows(world, unknowns, 1e-3, 0.0);
  ASSERT_EQ(unknowns.size(), 2u);
  EXPECT_EQ(unknowns[1], upper);
  ASSERT_EQ(rows.size(), 2u);
  const RigidBody<2>& a = *world.get<RigidBody<2>>(lower);
  const RigidBody<2>& b = *world.get<RigidBody<2>>(upper);
  const Vec<2> pin(0.12, 0.5);
  double worstCommon = 0, worstTurn = 0, largestSlide = 0;
  for (const RigidConstraintRow<2>& r : rows) {
    const AngularVec<2> W(1.3);
    worstCommon = std::max(worstCommon, std::abs(rowVelocity<2>(r, lower, commonTwist<2>(a, Vec<2>(0.2, -0.7), W),
                                                                commonTwist<2>(b, Vec<2>(0.2, -0.7), W))));
    Twist<2> turn;
    const Vec<2> arm = b.x - pin;
    turn << -arm.y(), arm.x(), 1.0;
    worstTurn = std::max(worstTurn, std::abs(rowVelocity<2>(r, lower, Twist<2>::Zero(), turn)));
    Twist<2> slide(0.6, 0.8, 0.0);
    largestSlide = std::max(largestSlide, std::abs(rowVelocity<2>(r, lower, Twist<2>::Zero(), slide)));
  }
  std::printf("2-D pin: common motion %.1e, turn about the pin %.1e, slide %.2f\n", worstCommon, worstTurn, largestSlide);
  EXPECT_LT(worstCommon, 1e-12);
  EXPECT_LT(worstTurn, 1e-12);
  EXPECT_GT(largestSlide, 0.5);
}

// density_ratio_light_box: an 8 kg block lands on a 0.032 kg box lying on the ground. Held by the
// ground inside the damping solves, the box no longer moves with the block's held particles as if
// it were free, and the block's damping sees its bottom stopped: the kinetic energy left over the
// last 0.3 s averages 4.2e-4 J (7.2e-4 J with the box free in the solves).
TEST(DampingRigidRows, LightBoxUnderBlockSettlesWithGroundRows) {
  const Registry registry = builtins();
  Simulation<3> sim(loadScene(kScenes + "density_ratio_light_box.json"), registry);
  double sum = 0;
  int count = 0;
  while (!sim.finished()) {
    const auto& m = sim.step();
    if (sim.time() >= 0.7) {
      sum += test::diagnostic(m, "kinetic_energy");
      ++count;
    }
  }
  ASSERT_GT(count, 10);
  std::printf("light box under block: mean kinetic energy over [0.7, 1] s %.3e J (%d steps)\n", sum / count, count);
  EXPECT_LT(sum / count, 5.5e-4);
}
