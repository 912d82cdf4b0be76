// Static boxes reaching down through the ground they stand on (solvers/collision/grounded_box.h):
// which boxes are extended, that every face above the ground stays where it was, and that the
// narrow phase then pushes a body at a wall's foot out of the wall's side, not into the ground.
#include "solvers/collision/grounded_box.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "solvers/collision/geometry.h"
#include "solvers/collision/narrow_phase.h"
#include "support/collision_shapes.h"

namespace {

using namespace monolith::solvers::collision;
using namespace monolith::test;
using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

constexpr double kTight = 1e-12;

// The box's extent [low, high] along a world direction n, centred at pose.x + pose.R * shift.
std::pair<double, double> extentAlong(const Geometry<3>& box, const Pose<3>& pose, const Vec3& shift, const Vec3& n) {
  const double c = n.dot(pose.x + pose.R * shift);
  double r = 0;
  for (int i = 0; i < 3; ++i) r += box.halfExtents(i) * std::abs(n.dot(pose.R.col(i)));
  return {c - r, c + r};
}

const std::vector<HalfSpaceInWorld<3>> kGround{{Vec3::UnitY(), Vec3::Zero()}};

}  // namespace

TEST(GroundedBox, AWallOnTheGroundReachesDownByItsLargestDimensionAndKeepsItsTop) {
  Geometry<3> wall = box3(0.1, 1, 2);  // 2 m tall, 4 m long
  const Pose<3> pose = at(Vec3(3, 1, 0));
  const Vec3 shift = extendBoxThroughGround<3>(wall, pose, kGround, 1e-5);
  EXPECT_NEAR(shift.y(), -2, kTight);  // half of 2 * 2 m
  EXPECT_EQ(shift.x(), 0);
  EXPECT_EQ(shift.z(), 0);
  EXPECT_NEAR(wall.halfExtents.y(), 3, kTight);
  EXPECT_EQ(wall.halfExtents.x(), 0.1);
  EXPECT_EQ(wall.halfExtents.z(), 2);
  const auto [low, high] = extentAlong(wall, pose, shift, Vec3::UnitY());
  EXPECT_NEAR(high, 2, kTight);  // the top where it was
  EXPECT_NEAR(low, -4, kTight);  // 4 m into the ground
}

TEST(GroundedBox, ATurnedBoxIsExtendedAlongTheBodyAxisThatPointsDown) {
  // Body x along world -y: the face at body +x is the bottom one.
  Geometry<3> wall = box3(1, 0.1, 0.5);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  const Pose<3> pose = at(Vec3(0, 1, 0), R);
  const Vec3 shift = extendBoxThroughGround<3>(wall, pose, kGround, 1e-5);
  EXPECT_NEAR(wall.halfExtents.x(), 2, kTight);
  EXPECT_NEAR((pose.R * shift).y(), -1, kTight);
  const auto [low, high] = extentAlong(wall, pose, shift, Vec3::UnitY());
  EXPECT_NEAR(high, 2, kTight);
  EXPECT_NEAR(low, -2, kTight);
}

TEST(GroundedBox, OnlyBoxesStandingOnOrInTheGroundAreExtended) {
  auto unchanged = [](Geometry<3> g, const Pose<3>& pose) {
    const Geometry<3> before = g;
    const Vec3 shift = extendBoxThroughGround<3>(g, pose, kGround, 1e-5);
    return shift == Vec3::Zero() && g.halfExtents == before.halfExtents;
  };
  EXPECT_TRUE(unchanged(box3(0.5, 0.5, 0.5), at(Vec3(0, 0.5 + 2e-5, 0))));  // hovering past the tolerance
  EXPECT_FALSE(unchanged(box3(0.5, 0.5, 0.5), at(Vec3(0, 0.5 + 5e-6, 0))));  // within it
  EXPECT_FALSE(unchanged(box3(0.5, 0.5, 0.5), at(Vec3(0, 0.3, 0))));  // sunk 20 cm
  EXPECT_TRUE(unchanged(box3(0.5, 0.5, 0.5), at(Vec3(0, -0.1, 0))));  // centre in the ground
  const Eigen::Matrix3d tilted = Eigen::AngleAxisd(0.1, Vec3::UnitX()).toRotationMatrix();
  EXPECT_TRUE(unchanged(box3(0.5, 0.5, 0.5), at(Vec3(0, 0.5, 0), tilted)));  // no face on the plane
  EXPECT_TRUE(unchanged(sphere3(0.5), at(Vec3(0, 0.5, 0))));
}

TEST(GroundedBox, TwoGroundsExtendTwoAxes) {
  // A box in the corner of a floor (y = 0) and a wall half-space (x = 0, solid at x < 0).
  const std::vector<HalfSpaceInWorld<3>> grounds{{Vec3::UnitY(), Vec3::Zero()}, {Vec3::UnitX(), Vec3::Zero()}};
  Geometry<3> box = box3(0.5, 0.25, 1);
  const Vec3 shift = extendBoxThroughGround<3>(box, at(Vec3(0.5, 0.25, 0)), grounds, 1e-5);
  EXPECT_NEAR(shift.x(), -1, kTight);
  EXPECT_NEAR(shift.y(), -1, kTight);
  EXPECT_EQ(shift.z(), 0);
}

TEST(GroundedBox, In2DTheSame) {
  Geometry<2> wall = box2(0.1, 1);
  Pose<2> pose;
  pose.x = Vec2(2, 1);
  const Vec2 shift = extendBoxThroughGround<2>(wall, pose, {{Vec2::UnitY(), Vec2::Zero()}}, 1e-5);
  EXPECT_NEAR(shift.y(), -1, kTight);
  EXPECT_NEAR(wall.halfExtents.y(), 2, kTight);
  EXPECT_EQ(wall.halfExtents.x(), 0.1);
}

TEST(GroundedBox, ANeedleAtTheFootOfAGroundedWallIsPushedOutOfItsSideNotDown) {
  // The needle of PushOutRounds.ANeedleAtAWallsFoot...: 1 cm thick, 1 mm into the ground and 5
  // cm into the wall (wall: z < 0). The wall as the scene gives it reports its bottom face, 9 mm
  // straight down; reaching through the ground it reports its inner face, 5 cm along +z.
  const Geometry<3> given = box3(1, 1, 0.1);
  const Pose<3> wallPose = at(Vec3(0, 1, -0.1));
  Geometry<3> grounded = given;
  const Vec3 shift = extendBoxThroughGround<3>(grounded, wallPose, kGround, 1e-5);
  const PreparedGeometry<3> needle(box3(0.005, 0.005, 0.1)), asGiven(given), extended(grounded);
  const Pose<3> needlePose = at(Vec3(0, 0.004, 0.05));
  auto deepest = [&](const PreparedGeometry<3>& wall, const Pose<3>& pose) {
    std::vector<ContactPoint<3>> points;
    findContacts<3>(needle, needlePose, wall, pose, ContactQuery{}, points);  // normals out of the wall
    ContactPoint<3> best;
    best.depth = -1;
    for (const auto& p : points)
      if (p.depth > best.depth) best = p;
    return best;
  };
  const ContactPoint<3> before = deepest(asGiven, wallPose);
  EXPECT_NEAR(before.normal.y(), -1, 1e-9);
  EXPECT_NEAR(before.depth, 0.009, 1e-9);
  const ContactPoint<3> after = deepest(extended, at(wallPose.x + shift));
  EXPECT_NEAR(after.normal.z(), 1, 1e-9);
  EXPECT_NEAR(after.depth, 0.05, 1e-9);
}
