// Static boxes reaching down through the ground they stand on (solvers/collision/grounded_box.h):
// which boxes are extended, that every face above the ground stays where it was, and that the
// narrow phase then pushes a body at a wall's foot out of the wall's side, not into the ground.
#include "solvers/collision/grounded_box.h"

#include <gtest/gtest.h>

#include <algorithm>
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

namespace {

// A floor slab 10 m square with its top face at y = 0, `thickness` deep.
BoxInWorld<3> floorSlab(double thickness) {
  return {at(Vec3(0, -0.5 * thickness, 0)), Vec3(5, 0.5 * thickness, 5)};
}

}  // namespace

TEST(GroundedBox, AWallOnAFloorBoxReachesIntoItNoFurtherThanItsFarFace) {
  for (const auto& [thickness, expectedLow] : {std::pair{6.0, -4.0}, std::pair{0.1, -0.1}}) {
    Geometry<3> wall = box3(0.1, 1, 2);
    const Pose<3> pose = at(Vec3(3, 1, 0));
    const Vec3 shift = extendBoxThroughGround<3>(wall, pose, {}, 1e-5, {floorSlab(thickness)});
    const auto [low, high] = extentAlong(wall, pose, shift, Vec3::UnitY());
    EXPECT_NEAR(high, 2, kTight) << thickness;  // the top where it was
    EXPECT_NEAR(low, expectedLow, kTight) << thickness;  // its own size down, or to the slab's bottom
    EXPECT_EQ(shift.x(), 0);
    EXPECT_EQ(shift.z(), 0);
    EXPECT_EQ(wall.halfExtents.x(), 0.1);
    EXPECT_EQ(wall.halfExtents.z(), 2);
  }
}

TEST(GroundedBox, OnlyABoxWhoseFaceLiesOnTheSupportsFaceIsExtended) {
  auto unchanged = [](Geometry<3> g, const Pose<3>& pose, const std::vector<BoxInWorld<3>>& supports) {
    const Geometry<3> before = g;
    const Vec3 shift = extendBoxThroughGround<3>(g, pose, {}, 1e-5, supports);
    return shift == Vec3::Zero() && g.halfExtents == before.halfExtents;
  };
  const std::vector<BoxInWorld<3>> floor{floorSlab(1)};
  EXPECT_FALSE(unchanged(box3(0.1, 1, 2), at(Vec3(4.9, 1, 0)), floor));  // flush with the slab's edge
  EXPECT_TRUE(unchanged(box3(0.1, 1, 2), at(Vec3(4.95, 1, 0)), floor));  // overhanging it by 5 cm
  EXPECT_TRUE(unchanged(box3(0.1, 1, 2), at(Vec3(0, 1 + 2e-5, 0)), floor));  // hovering past the tolerance
  EXPECT_FALSE(unchanged(box3(0.1, 1, 2), at(Vec3(0, 0.8, 0)), floor));  // sunk 20 cm
  EXPECT_TRUE(unchanged(box3(0.1, 1, 2), at(Vec3(0, -0.6, 0)), floor));  // centre in the slab
  const Eigen::Matrix3d tilted = Eigen::AngleAxisd(0.1, Vec3::UnitX()).toRotationMatrix();
  EXPECT_TRUE(unchanged(box3(0.1, 1, 2), at(Vec3(0, 1.2, 0), tilted), floor));  // no face on the slab's
  const BoxInWorld<3> itself{at(Vec3(0, 1, 0)), Vec3(0.1, 1, 2)};
  EXPECT_TRUE(unchanged(box3(0.1, 1, 2), itself.pose, {itself}));  // the box is no support of its own
  // A turned slab: the wall stands on its face, whatever the slab's frame.
  const Eigen::Matrix3d turned = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  const BoxInWorld<3> turnedSlab{at(Vec3(0, -0.5, 0), turned), Vec3(0.5, 5, 5)};
  EXPECT_FALSE(unchanged(box3(0.1, 1, 2), at(Vec3(3, 1, 0)), {turnedSlab}));
}

TEST(GroundedBox, AGroundedFloorBoxIsNoObstacleToTheWallOnIt) {
  // Plane first, then the slab: a wall standing on a slab that lies on the ground reaches into
  // the slab; the slab itself reaches through the plane.
  const std::vector<HalfSpaceInWorld<3>> ground{{Vec3::UnitY(), Vec3(0, -1, 0)}};
  Geometry<3> slab = box3(5, 0.5, 5);
  const Vec3 slabShift = extendBoxThroughGround<3>(slab, at(Vec3(0, -0.5, 0)), ground, 1e-5, {floorSlab(1)});
  EXPECT_NEAR(slabShift.y(), -5, kTight);
  Geometry<3> wall = box3(0.1, 1, 2);
  const Vec3 shift = extendBoxThroughGround<3>(wall, at(Vec3(3, 1, 0)), ground, 1e-5, {floorSlab(1)});
  EXPECT_NEAR(shift.y(), -0.5, kTight);  // down to the slab's bottom, 1 m
}

TEST(GroundedBox, In2DAWallOnAFloorBox) {
  Geometry<2> wall = box2(0.1, 1);
  Pose<2> pose;
  pose.x = Vec2(2, 1);
  BoxInWorld<2> floor;
  floor.pose.x = Vec2(0, -0.25);
  floor.halfExtents = Vec2(5, 0.25);
  const Vec2 shift = extendBoxThroughGround<2>(wall, pose, {}, 1e-5, {floor});
  EXPECT_NEAR(shift.y(), -0.25, kTight);
  EXPECT_NEAR(wall.halfExtents.y(), 1.25, kTight);
  pose.x = Vec2(5, 1);  // half over the edge
  Geometry<2> overhanging = box2(0.1, 1);
  EXPECT_EQ(extendBoxThroughGround<2>(overhanging, pose, {}, 1e-5, {floor}), Vec2::Zero());
}

TEST(GroundedBox, ANeedleAtTheFootOfAWallOnAFloorBoxIsPushedOutOfTheWallsSide) {
  // As ANeedleAtTheFootOfAGroundedWall... with a 1 m floor slab instead of the plane.
  const Geometry<3> given = box3(1, 1, 0.1);
  const Pose<3> wallPose = at(Vec3(0, 1, -0.1));
  Geometry<3> grounded = given;
  const Vec3 shift = extendBoxThroughGround<3>(grounded, wallPose, {}, 1e-5, {floorSlab(1)});
  EXPECT_NEAR(shift.y(), -0.5, kTight);
  const PreparedGeometry<3> needle(box3(0.005, 0.005, 0.1)), extended(grounded);
  std::vector<ContactPoint<3>> points;
  findContacts<3>(needle, at(Vec3(0, 0.004, 0.05)), extended, at(wallPose.x + shift), ContactQuery{}, points);
  ASSERT_FALSE(points.empty());
  const auto deepest = *std::max_element(points.begin(), points.end(),
                                         [](const auto& p, const auto& q) { return p.depth < q.depth; });
  EXPECT_NEAR(deepest.normal.z(), 1, 1e-9);
  EXPECT_NEAR(deepest.depth, 0.05, 1e-9);
}
