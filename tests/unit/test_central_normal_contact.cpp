// The normal-only central-body contact of thesis Sec. 4.7.3, eq. (4.3)-(4.4)
// (solvers/contact/central_normal_contact.h): a rigid body and every particle touching it solved
// together. Checked on random configurations: every pushed contact ends at its target relative
// normal velocity, no contact pulls or is left approaching, the body's impulse is the opposite of
// the particles' (momentum), the kinetic energy never rises (inelastic), and the closed form of a
// head-on impact.
#include <gtest/gtest.h>

#include <random>

#include "solvers/contact/central_normal_contact.h"
#include "support/random_rigid.h"

namespace {

using namespace monolith::solvers::contact;
using monolith::test::randomVec;

template <int d>
struct Case {
  CentralNormalBody<d> body;
  std::vector<CentralNormalOuter<d>> outers;
  std::vector<Vec<d>> particleVelocity;  // absolute; the body starts at rest
};

template <int d>
Case<d> randomCase(std::mt19937& rng, double massRatio) {
  std::uniform_real_distribution<double> u(0.2, 1.0);
  std::uniform_int_distribution<int> count(1, 12);
  Case<d> c;
  c.body.mass = u(rng);
  c.body.inertia = monolith::test::randomInertiaLike<d>(rng, 0.2, 1.0) * c.body.mass;
  const int n = count(rng);
  for (int o = 0; o < n; ++o) {
    CentralNormalOuter<d> out;
    out.mass = massRatio * c.body.mass * u(rng);
    out.r = randomVec<d>(rng);
    out.n = randomVec<d>(rng).normalized();
    c.particleVelocity.push_back(randomVec<d>(rng));
    out.normalVelocity = c.particleVelocity.back().dot(out.n);
    c.outers.push_back(out);
  }
  return c;
}

template <int d>
void checkRandom(double massRatio) {
  std::mt19937 rng(7 + d);
  for (int trial = 0; trial < 200; ++trial) {
    const Case<d> c = randomCase<d>(rng, massRatio);
    const CentralNormalResult<d> r = solveCentralNormalContact<d>(c.body, c.outers);
    // The body's velocity change from the impulses it received.
    const Vec<d> dv = r.bodyImpulse / c.body.mass;
    const AngVec<d> dw = c.body.inertia.inverse() * r.bodyAngularImpulse;
    Vec<d> sum = Vec<d>::Zero();
    AngVec<d> torque = AngVec<d>::Zero();
    double kineticBefore = 0, kineticAfter = 0.5 * c.body.mass * dv.squaredNorm() + 0.5 * r.bodyAngularImpulse.dot(dw);
    for (std::size_t o = 0; o < c.outers.size(); ++o) {
      const CentralNormalOuter<d>& out = c.outers[o];
      ASSERT_GE(r.lambda[o], 0.0) << "contact pulls";
      const Vec<d> after = c.particleVelocity[o] + (r.lambda[o] / out.mass) * out.n;
      const double un = (after - dv - angularCross<d>(dw, out.r)).dot(out.n);
      // Scale of the velocities is 1: round-off of a 6x6 solve with mass ratios up to 1e3.
      if (r.lambda[o] > 0) EXPECT_NEAR(un, 0.0, 1e-9) << "trial " << trial;
      else EXPECT_GE(un, -1e-9) << "left approaching, trial " << trial;
      sum += r.lambda[o] * out.n;
      torque += cross<d>(out.r, r.lambda[o] * out.n);
      kineticBefore += 0.5 * out.mass * c.particleVelocity[o].squaredNorm();
      kineticAfter += 0.5 * out.mass * after.squaredNorm();
    }
    EXPECT_LT((sum + r.bodyImpulse).norm(), 1e-12 * (1 + sum.norm()));
    EXPECT_LT((torque + r.bodyAngularImpulse).norm(), 1e-12 * (1 + torque.norm()));
    EXPECT_LE(kineticAfter, kineticBefore * (1 + 1e-12) + 1e-14) << "trial " << trial;
  }
}

TEST(CentralNormalContact, RandomContactsStopWithoutPullingIn2D) {
  for (double ratio : {1e-3, 1.0, 1e3}) checkRandom<2>(ratio);
}

TEST(CentralNormalContact, RandomContactsStopWithoutPullingIn3D) {
  for (double ratio : {1e-3, 1.0, 1e3}) checkRandom<3>(ratio);
}

// Head-on, the arm along the normal (no turning): particle m at u onto a body M at rest ends at
// the common velocity m u / (m + M), for light and heavy bodies alike.
TEST(CentralNormalContact, HeadOnImpactReachesTheCommonVelocity) {
  for (double M : {1e-3, 1.0, 1e3}) {
    CentralNormalBody<3> body;
    body.mass = M;
    body.inertia = Eigen::Matrix3d::Identity() * M;
    CentralNormalOuter<3> p;
    p.mass = 1;
    p.n = Eigen::Vector3d::UnitY();
    p.r = 0.5 * p.n;
    p.normalVelocity = -2;
    const auto r = solveCentralNormalContact<3>(body, {p});
    const double common = -2.0 / (1 + M);
    EXPECT_NEAR(-2 + r.lambda[0], common, 1e-12 * (1 + std::abs(common)));
    EXPECT_NEAR(r.bodyImpulse.y() / M, common, 1e-12 * (1 + std::abs(common)));
  }
}

// A static or kinematic central body decouples: each approaching particle stops by itself and
// a separating one is left alone.
TEST(CentralNormalContact, InfiniteBodyStopsEachParticleAlone) {
  CentralNormalBody<2> body;
  body.infinite = true;
  CentralNormalOuter<2> a, b;
  a.mass = 2, a.n = Eigen::Vector2d::UnitY(), a.normalVelocity = -1.5;
  b.mass = 3, b.n = Eigen::Vector2d::UnitX(), b.normalVelocity = 0.5;
  const auto r = solveCentralNormalContact<2>(body, {a, b});
  EXPECT_DOUBLE_EQ(r.lambda[0], 3.0);
  EXPECT_DOUBLE_EQ(r.lambda[1], 0.0);
  EXPECT_EQ(r.active, 1);
}

// Equation (4.4) by hand for two particles pressing a free body at its two ends: the body
// takes both without turning, and both particles stop relative to it.
TEST(CentralNormalContact, TwoEndsPressTheBodyWithoutTurningIt) {
  CentralNormalBody<2> body;
  body.mass = 4;
  body.inertia(0, 0) = 1;
  std::vector<CentralNormalOuter<2>> o(2);
  for (int k = 0; k < 2; ++k) {
    o[k].mass = 1;
    o[k].n = -Eigen::Vector2d::UnitY();  // particles below the body, normal out of the body
    o[k].r = Eigen::Vector2d(k == 0 ? -1 : 1, -0.5);
    o[k].normalVelocity = -1;  // moving up into it
  }
  const auto r = solveCentralNormalContact<2>(body, o);
  // Momentum: the body and both particles at the common velocity 2 / 6 upwards.
  EXPECT_NEAR(r.bodyImpulse.y() / body.mass, 1.0 / 3, 1e-14);
  EXPECT_NEAR(r.bodyAngularImpulse(0), 0.0, 1e-14);
  EXPECT_NEAR(r.lambda[0], r.lambda[1], 1e-14);
}

}  // namespace
