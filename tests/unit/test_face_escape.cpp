// The way out of a static box through one of its faces (solvers/collision/face_escape.h), which
// push-out's later rounds use where a wall's least-penetration direction leads into the ground:
// closed-form pushes for a needle poking into a wall's foot, the avoided directions, a turned
// box, and the cases with no answer.
#include "solvers/collision/face_escape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "solvers/collision/geometry.h"
#include "support/collision_shapes.h"

namespace {

using namespace monolith::solvers::collision;
using namespace monolith::test;
using Vec3 = Eigen::Vector3d;

constexpr double kTight = 1e-12;

// A wall 2 m high and 0.2 m thick standing on the ground plane y = 0 (its inner face at z = 0),
// and a needle 1 cm thick lying along z at its foot, 1 mm into the ground and 5 cm into the wall.
struct WallFoot {
  PreparedGeometry<3> wall{box3(1, 1, 0.1)};
  Pose<3> wallPose = at(Vec3(0, 1, -0.1));
  PreparedGeometry<3> needle{box3(0.005, 0.005, 0.1)};
  Pose<3> needlePose = at(Vec3(0.3, 0.004, 0.05));
};

TEST(FaceEscape, WithoutAvoidedDirectionsTheLeastPushIsTheBottomFaceIntoTheGround) {
  // Along the wall's bottom face (outward normal -y) the needle's top (y = 0.009) must come down
  // to y = 0: 9 mm, less than the 5 cm back out of the inner face. That is the direction the
  // narrow phase reports, and it points into the ground.
  const WallFoot s;
  ContactPoint<3> c;
  ASSERT_TRUE(escapeThroughBoxFace<3>(s.wall, s.wallPose, s.needle, s.needlePose, {}, c));
  EXPECT_NEAR(c.depth, 0.009, kTight);
  EXPECT_NEAR((c.normal - Vec3(0, 1, 0)).norm(), 0, kTight);  // out of the needle towards the wall
}

TEST(FaceEscape, AvoidingTheGroundsPushItLeavesThroughTheInnerFace) {
  const WallFoot s;
  ContactPoint<3> c;
  ASSERT_TRUE(escapeThroughBoxFace<3>(s.wall, s.wallPose, s.needle, s.needlePose, {Vec3(0, 1, 0)}, c));
  // The needle's far end is at z = -0.05: 5 cm back out along +z; reported as findContacts(wall,
  // needle) reports, with the normal out of the needle towards the wall.
  EXPECT_NEAR(c.depth, 0.05, kTight);
  EXPECT_NEAR((c.normal - Vec3(0, 0, -1)).norm(), 0, kTight);
  // The point lies midway between the needle's deepest point past the face and the face.
  EXPECT_NEAR(c.point.z(), -0.025, kTight);
  EXPECT_NEAR(c.pointOnB().z(), -0.05, kTight);
  EXPECT_LE(std::abs(c.point.x() - 0.3), 0.005 + kTight);
}

TEST(FaceEscape, AFaceWithinSixtyDegreesOfAnAvoidedDirectionIsNotTaken) {
  const WallFoot s;
  ContactPoint<3> c;
  // Avoiding +z as well as +y leaves the side faces (+-x, the needle 0.7 m and 1.3 m from them
  // after its own half width) and the far face (-z, 0.2 + 0.15 m).
  ASSERT_TRUE(escapeThroughBoxFace<3>(s.wall, s.wallPose, s.needle, s.needlePose, {Vec3(0, 1, 0), Vec3(0, 0, -1)}, c));
  EXPECT_NEAR(c.depth, 0.35, kTight);
  EXPECT_NEAR((c.normal - Vec3(0, 0, 1)).norm(), 0, kTight);
  // A direction 59 degrees off the inner face's normal still rules it out; 61 degrees does not.
  const double a59 = 59 * M_PI / 180, a61 = 61 * M_PI / 180;
  ASSERT_TRUE(escapeThroughBoxFace<3>(s.wall, s.wallPose, s.needle, s.needlePose,
                                   {Vec3(0, 1, 0), Vec3(0, -std::sin(a59), -std::cos(a59))}, c));
  EXPECT_NEAR(c.depth, 0.35, kTight);
  ASSERT_TRUE(escapeThroughBoxFace<3>(s.wall, s.wallPose, s.needle, s.needlePose,
                                   {Vec3(0, 1, 0), Vec3(0, -std::sin(a61), -std::cos(a61))}, c));
  EXPECT_NEAR(c.depth, 0.05, kTight);
}

TEST(FaceEscape, ATurnedWallAndASphereGiveTheClosedFormPush) {
  // The wall turned 90 degrees about y (its thin axis now along x, inner face at x = 0.5), a
  // ball of radius 0.1 centred 4 cm inside: 0.14 m out along +x.
  const PreparedGeometry<3> wall(box3(1, 1, 0.1));
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();
  const Pose<3> wallPose = at(Vec3(0.4, 1, 0), R);
  const PreparedGeometry<3> ball(sphere3(0.1));
  ContactPoint<3> c;
  ASSERT_TRUE(escapeThroughBoxFace<3>(wall, wallPose, ball, at(Vec3(0.46, 0.05, 0.2)), {Vec3(0, 1, 0)}, c));
  EXPECT_NEAR(c.depth, 0.14, 1e-12);
  EXPECT_NEAR((c.normal - Vec3(-1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((c.pointOnB() - Vec3(0.36, 0.05, 0.2)).norm(), 0, 1e-12);
}

TEST(FaceEscape, InTwoDimensionsADiskAndAPolygonLeaveThroughTheWallsInnerFace) {
  // A 2-D wall [-0.2, 0] x [0, 2] on the ground line; a disk of radius 0.05 centred at (-0.06,
  // 0.04): 9 cm down through the bottom face (the least push), 11 cm out along +x when the
  // bottom face, pointing into the ground, is avoided.
  const PreparedGeometry<2> wall(box2(0.1, 1));
  Pose<2> wallPose;
  wallPose.x = Eigen::Vector2d(-0.1, 1);
  const PreparedGeometry<2> disk(monolith::test::disk(0.05));
  Pose<2> diskPose;
  diskPose.x = Eigen::Vector2d(-0.06, 0.04);
  ContactPoint<2> c;
  ASSERT_TRUE(escapeThroughBoxFace<2>(wall, wallPose, disk, diskPose, {}, c));
  EXPECT_NEAR(c.depth, 0.09, kTight);
  EXPECT_NEAR((c.normal - Eigen::Vector2d(0, 1)).norm(), 0, kTight);
  ASSERT_TRUE(escapeThroughBoxFace<2>(wall, wallPose, disk, diskPose, {Eigen::Vector2d(0, 1)}, c));
  EXPECT_NEAR(c.depth, 0.11, kTight);
  EXPECT_NEAR((c.normal - Eigen::Vector2d(-1, 0)).norm(), 0, kTight);
  EXPECT_NEAR((c.pointOnB() - Eigen::Vector2d(-0.11, 0.04)).norm(), 0, kTight);
  // A triangle turned half a turn and placed at (-0.01, 0.05): its vertex (0.03, 0) lands at
  // (-0.04, 0.05), the furthest inside; the others at x = 0.02 are outside the wall.
  Geometry<2> triangle;
  triangle.type = GeometryType::Convex;
  triangle.vertices = {Eigen::Vector2d(0.03, 0), Eigen::Vector2d(-0.03, 0.03), Eigen::Vector2d(-0.03, -0.03)};
  const PreparedGeometry<2> polygon(triangle);
  Pose<2> polygonPose;
  polygonPose.x = Eigen::Vector2d(-0.01, 0.05);
  polygonPose.R = Eigen::Rotation2Dd(M_PI).toRotationMatrix();
  ASSERT_TRUE(escapeThroughBoxFace<2>(wall, wallPose, polygon, polygonPose, {Eigen::Vector2d(0, 1)}, c));
  EXPECT_NEAR(c.depth, 0.04, kTight);
  EXPECT_NEAR((c.pointOnB() - Eigen::Vector2d(-0.04, 0.05)).norm(), 0, kTight);
}

TEST(FaceEscape, NoAnswerOutsideTheBoxOrWhenEveryFaceIsRuledOut) {
  const WallFoot s;
  ContactPoint<3> c;
  // A needle clear of the wall (1 cm in front of its inner face).
  EXPECT_FALSE(escapeThroughBoxFace<3>(s.wall, s.wallPose, s.needle, at(Vec3(0.3, 0.004, 0.11)), {Vec3(0, 1, 0)}, c));
  // Every face within 60 degrees of one of the six axis directions.
  const std::vector<Vec3> all = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
  EXPECT_FALSE(escapeThroughBoxFace<3>(s.wall, s.wallPose, s.needle, s.needlePose, all, c));
  // Only a box has faces to leave through.
  EXPECT_THROW(escapeThroughBoxFace<3>(PreparedGeometry<3>(sphere3(0.1)), s.wallPose, s.needle, s.needlePose, {}, c),
               std::invalid_argument);
}

}  // namespace
