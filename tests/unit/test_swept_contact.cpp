// First contact along a step's motion (solvers/collision/swept_contact.h): the time of impact
// of translating and turning bodies against closed forms, thin bodies that the end poses alone
// would let pass, misses, and the motion and size rules the collision step relies on.
#include "solvers/collision/swept_contact.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "solvers/collision/narrow_phase.h"
#include "support/collision_shapes.h"

namespace {

using namespace monolith::solvers::collision;
using namespace monolith::test;  // box3, sphere3, halfSpace, box2, disk
using Vec3 = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

StepMotion<3> still(const Vec3& x) {
  StepMotion<3> m;
  m.start.x = x;
  return m;
}

StepMotion<3> moving(const Vec3& x, const Vec3& translation, const Vec3& rotation = Vec3::Zero()) {
  StepMotion<3> m = still(x);
  m.translation = translation;
  m.rotation = rotation;
  return m;
}

SweptQuery queryFor(double size) {
  SweptQuery q;
  q.sampleTravel = 0.5 * size;
  return q;
}

TEST(SweptContact, PlateThrownThroughAThinShelfIsCaughtWhereItFirstTouches) {
  // A 4 cm plate moves 0.5 m down in the step, from 0.1 m above a 4 cm shelf to 0.36 m below
  // its top: neither end pose overlaps the shelf, so the candidate test misses it entirely.
  const PreparedGeometry<3> plate(box3(0.5, 0.02, 0.25)), shelf(box3(0.5, 0.02, 0.25));
  const StepMotion<3> a = moving(Vec3(0.1, 0.14, 0.05), Vec3(0, -0.5, 0)), b = still(Vec3::Zero());
  ASSERT_FALSE(overlaps<3>(plate, a.at(0), shelf, b.at(0)));
  ASSERT_FALSE(overlaps<3>(plate, a.at(1), shelf, b.at(1)));
  const double s = firstContactFraction<3>(plate, a, shelf, b, queryFor(0.04));
  // Faces meet when the plate's bottom (0.14 - 0.02 - 0.5 s) reaches the shelf's top (0.02).
  const double exact = 0.1 / 0.5;
  EXPECT_GE(s, exact);
  EXPECT_LT(s - exact, 0.5 * 0.04 / 0.5 / 4096 + 1e-12) << "bracket of 12 bisections of one sample";
  EXPECT_TRUE(overlaps<3>(plate, a.at(s), shelf, b.at(s)));
}

TEST(SweptContact, SphereOntoTheGroundAndMisses) {
  const PreparedGeometry<3> ball(sphere3(0.1)), plane(halfSpace<3>(Vec3::UnitY(), 0));
  // Centre from 1 m to 0.05 m: touches at 1 - 0.1 = 0.9 m of travel out of 0.95.
  const double s = firstContactFraction<3>(ball, moving(Vec3(0, 1, 0), Vec3(0, -0.95, 0)), plane,
                                           still(Vec3::Zero()), queryFor(0.2));
  EXPECT_NEAR(s, 0.9 / 0.95, 0.1 / 0.95 / 4096 + 1e-12);
  // Moving sideways above it: never touches.
  EXPECT_EQ(-1.0, firstContactFraction<3>(ball, moving(Vec3(0, 0.5, 0), Vec3(3, 0, 0)), plane, still(Vec3::Zero()),
                                          queryFor(0.2)));
  // Flying past a thin plate beside it: never touches.
  const PreparedGeometry<3> plate(box3(0.5, 0.02, 0.25));
  EXPECT_EQ(-1.0, firstContactFraction<3>(ball, moving(Vec3(1.0, 1, 0), Vec3(0, -2, 0)), plate, still(Vec3::Zero()),
                                          queryFor(0.04)));
}

TEST(SweptContact, OverlappingAtTheStartIsContactAtZero) {
  const PreparedGeometry<3> a(box3(0.5, 0.5, 0.5)), b(box3(0.5, 0.5, 0.5));
  EXPECT_EQ(0.0, firstContactFraction<3>(a, moving(Vec3(0, 0.99, 0), Vec3(0, -1, 0)), b, still(Vec3::Zero()),
                                         queryFor(1.0)));
}

TEST(SweptContact, TurningBarSweepsThroughAThinPostAtTheRightAngle) {
  // A 2 m bar (4 cm thick) turns by 90 degrees about its centre in the step; a thin post stands
  // 0.6 m from the centre at 45 degrees. End poses (bar along x, then along z) miss the post.
  const PreparedGeometry<3> bar(box3(1.0, 0.02, 0.02)), post(box3(0.02, 0.5, 0.02));
  const Vec3 postAt(0.6 * std::cos(kPi / 4), 0, -0.6 * std::sin(kPi / 4));  // turning about +y takes +x to -z
  const StepMotion<3> a = moving(Vec3::Zero(), Vec3::Zero(), Vec3(0, kPi / 2, 0)), b = still(postAt);
  ASSERT_FALSE(overlaps<3>(bar, a.at(0), post, b.at(0)));
  ASSERT_FALSE(overlaps<3>(bar, a.at(1), post, b.at(1)));
  const double s = firstContactFraction<3>(bar, a, post, b, queryFor(0.04));
  // The bar's leading face (0.02 from its axis) meets the post's nearest edge; in angle that is
  // 45 degrees less the half widths seen from 0.6 m, i.e. about (pi/4 - 0.04/0.6) / (pi/2).
  EXPECT_GT(s, (kPi / 4 - 0.1) / (kPi / 2));
  EXPECT_LT(s, 0.5);
  EXPECT_TRUE(overlaps<3>(bar, a.at(s), post, b.at(s)));
  EXPECT_FALSE(overlaps<3>(bar, a.at(s - 1e-3), post, b.at(s - 1e-3)));
}

TEST(SweptContact, SizesAndTravelFollowTheRulesTheCollisionStepUses) {
  const PreparedGeometry<3> plate(box3(0.5, 0.02, 0.25)), plane(halfSpace<3>(Vec3::UnitY(), 0)), ball(sphere3(0.1));
  EXPECT_DOUBLE_EQ(0.04, tunnelingSize<3>(plate));
  EXPECT_DOUBLE_EQ(0.2, tunnelingSize<3>(ball));
  EXPECT_EQ(std::numeric_limits<double>::infinity(), tunnelingSize<3>(plane));
  // Relative translation plus angle times bounding radius; the still half-space adds nothing
  // (its infinite radius times a zero angle).
  const StepMotion<3> a = moving(Vec3::Zero(), Vec3(0.3, -0.4, 0), Vec3(0, 0, 2.0));
  EXPECT_DOUBLE_EQ(0.5 + 2.0 * std::sqrt(0.25 + 0.0004 + 0.0625), relativeTravel<3>(plate, a, plane, still(Vec3::Zero())));
  const StepMotion<3> b = moving(Vec3(5, 0, 0), Vec3(0.3, -0.4, 0));
  EXPECT_DOUBLE_EQ(0.2, relativeTravel<3>(ball, moving(Vec3::Zero(), Vec3(0.3, -0.2, 0)), ball, b));
  // The motion's end is the candidate pose: translated and turned by the rotation vector.
  const Pose<3> end = a.at(1.0);
  EXPECT_TRUE(end.x.isApprox(Vec3(0.3, -0.4, 0)));
  EXPECT_NEAR(std::cos(2.0), end.R(0, 0), 1e-15);
  EXPECT_NEAR(std::sin(2.0), end.R(1, 0), 1e-15);
}

TEST(SweptContact, TwoDimensionalDiskThroughAThinBar) {
  const PreparedGeometry<2> a(disk(0.05)), b(box2(1.0, 0.01));
  StepMotion<2> m, fixed;
  m.start.x = Eigen::Vector2d(0, 0.3);
  m.translation = Eigen::Vector2d(0, -0.6);
  const double s = firstContactFraction<2>(a, m, b, fixed, queryFor(0.02));
  EXPECT_NEAR(s, (0.3 - 0.06) / 0.6, 0.01 / 0.6 / 4096 + 1e-12);
}

}  // namespace
