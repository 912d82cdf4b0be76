// Tests for the impulse factor and the point impulse with restitution and Coulomb friction
// (thesis Sec. 2.3, notes 1.5): every check is on the bodies' velocities after applying the
// impulse, not on the formula that produced it.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <type_traits>

#include "support/random_rigid.h"
#include "solvers/contact/impulse.h"

namespace {

using namespace monolith::solvers::contact;

template <int d>
struct Body {
  double mass = 1;
  AngMat<d> inertia = AngMat<d>::Identity();  // world
  Vec<d> x = Vec<d>::Zero();
  Vec<d> v = Vec<d>::Zero();
  AngVec<d> w = AngVec<d>::Zero();
  bool infinite = false;

  Vec<d> pointVelocity(const Vec<d>& p) const { return v + angularCross<d>(w, p - x); }
  void apply(const Vec<d>& j, const Vec<d>& p) {
    if (infinite) return;
    v += j / mass;
    w += inertia.inverse() * cross<d>(p - x, j);
  }
  ImpulseBody<d> at(const Vec<d>& p) const {
    ImpulseBody<d> b;
    b.inverseMass = infinite ? 0 : 1 / mass;
    b.inverseInertia = infinite ? AngMat<d>::Zero() : AngMat<d>(inertia.inverse());
    b.r = p - x;
    return b;
  }
  Vec<d> linearMomentum() const { return mass * v; }
  AngVec<d> angularMomentumAboutOrigin() const {
    return cross<d>(x, Vec<d>(mass * v)) + inertia * w;
  }
};

using monolith::test::randomVec;

template <int d>
AngMat<d> randomInertia(std::mt19937& rng) {
  return monolith::test::randomInertiaLike<d>(rng, 0.5, 2.0);
}

template <int d>
Body<d> randomBody(std::mt19937& rng) {
  std::uniform_real_distribution<double> m(0.5, 3.0);
  Body<d> b;
  b.mass = m(rng);
  b.inertia = randomInertia<d>(rng);
  b.x = randomVec<d>(rng);
  b.v = randomVec<d>(rng);
  b.w = AngVec<d>(randomVec<kAngularDim<d>>(rng));
  return b;
}

// A pair A (above) and B in contact at p with normal n out of B, approaching along n.
template <int d>
struct Pair {
  Body<d> a, b;
  Vec<d> p, n;
  Mat<d> k() const { return impulseFactor<d>(a.at(p)) + impulseFactor<d>(b.at(p)); }
  Vec<d> relative() const { return a.pointVelocity(p) - b.pointVelocity(p); }
  void apply(const Vec<d>& j) {
    a.apply(j, p);
    b.apply(Vec<d>(-j), p);
  }
};

// Shift A's velocity along n so that the pair approaches with normal speed 1.
template <int d>
void makeApproaching(Pair<d>& pair) {
  pair.a.v -= (pair.relative().dot(pair.n) + 1) * pair.n;
}

template <int d>
Pair<d> randomApproachingPair(std::mt19937& rng) {
  Pair<d> pair;
  pair.a = randomBody<d>(rng);
  pair.b = randomBody<d>(rng);
  pair.p = randomVec<d>(rng);
  pair.n = randomVec<d>(rng).normalized();
  makeApproaching(pair);
  return pair;
}

template <int d>
Vec<d> tangential(const Vec<d>& v, const Vec<d>& n) {
  return v - v.dot(n) * n;
}

template <typename T>
class ContactImpulse : public ::testing::Test {};
using Dimensions = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(ContactImpulse, Dimensions);

TYPED_TEST(ContactImpulse, FactorIsSpdAndTheVelocityChangePerUnitImpulse) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Body<d> body = randomBody<d>(rng);
    const Vec<d> p = randomVec<d>(rng, 2);
    const Mat<d> k = impulseFactor<d>(body.at(p));
    EXPECT_LT((k - k.transpose()).norm(), 1e-14);
    Eigen::SelfAdjointEigenSolver<Mat<d>> eig;
    eig.computeDirect(k);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    // Column i is the point-velocity change of a small impulse h e_i, divided by h.
    const double h = 1e-3;
    for (int i = 0; i < d; ++i) {
      Body<d> kicked = body;
      kicked.apply(Vec<d>(h * Vec<d>::Unit(i)), p);
      const Vec<d> dv = (kicked.pointVelocity(p) - body.pointVelocity(p)) / h;
      EXPECT_LT((dv - k.col(i)).norm(), 1e-12 * k.norm());
    }
  }
}

TYPED_TEST(ContactImpulse, FrictionlessRestitutionAndMomentum) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(12);
  for (double e : {0.0, 0.5, 1.0}) {
    for (int trial = 0; trial < 10; ++trial) {
      Pair<d> pair = randomApproachingPair<d>(rng);
      const double vnBefore = pair.relative().dot(pair.n);
      const Vec<d> pBefore = pair.a.linearMomentum() + pair.b.linearMomentum();
      const AngVec<d> lBefore =
          pair.a.angularMomentumAboutOrigin() + pair.b.angularMomentumAboutOrigin();
      ImpulseSettings s;
      s.restitution = e;
      const Vec<d> j = pointImpulse<d>(pair.k(), pair.relative(), pair.n, s);
      EXPECT_LT(tangential<d>(j, pair.n).norm(), 1e-14 * j.norm());  // frictionless: along n
      pair.apply(j);
      EXPECT_NEAR(pair.relative().dot(pair.n), -e * vnBefore, 1e-12);
      EXPECT_LT((pair.a.linearMomentum() + pair.b.linearMomentum() - pBefore).norm(), 1e-12);
      EXPECT_LT(
          (pair.a.angularMomentumAboutOrigin() + pair.b.angularMomentumAboutOrigin() - lBefore)
              .norm(),
          1e-12);
    }
  }
}

TYPED_TEST(ContactImpulse, ContactRestitutionIsEpsilonTimesInelastic) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(13);
  const Pair<d> pair = randomApproachingPair<d>(rng);
  ImpulseSettings inelastic;
  const Vec<d> full = pointImpulse<d>(pair.k(), pair.relative(), pair.n, inelastic);
  for (double eps : {0.1, 0.5, 1.0}) {
    ImpulseSettings s;
    s.restitution = -1 + eps;
    const Vec<d> j = pointImpulse<d>(pair.k(), pair.relative(), pair.n, s);
    EXPECT_LT((j - eps * full).norm(), 1e-13 * full.norm()) << "eps " << eps;
    Pair<d> after = pair;
    after.apply(j);
    // Normal relative velocity -e v_n = (1 - eps) v_n: only part of the approach is removed.
    EXPECT_NEAR(after.relative().dot(pair.n), (1 - eps) * pair.relative().dot(pair.n), 1e-12);
  }
  // Also with friction (sticking): the tangential slip is removed, the normal part as above.
  ImpulseSettings sticky;
  sticky.restitution = -1 + 0.25;
  sticky.friction = 100;
  Pair<d> after = pair;
  after.apply(pointImpulse<d>(pair.k(), pair.relative(), pair.n, sticky));
  EXPECT_NEAR(after.relative().dot(pair.n), 0.75 * pair.relative().dot(pair.n), 1e-12);
  EXPECT_LT(tangential<d>(after.relative(), pair.n).norm(), 1e-12);
}

TYPED_TEST(ContactImpulse, StickingRemovesAllSlip) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(14);
  for (double e : {0.0, 0.5}) {
    for (int trial = 0; trial < 10; ++trial) {
      Pair<d> pair = randomApproachingPair<d>(rng);
      const Vec<d> before = pair.relative();
      const double vn = before.dot(pair.n);
      ImpulseSettings s;
      s.restitution = e;
      s.friction = 1e3;  // the sticking impulse always lies inside this cone
      const Vec<d> j = pointImpulse<d>(pair.k(), before, pair.n, s);
      EXPECT_GT(j.dot(pair.n), 0.0);
      pair.apply(j);
      EXPECT_LT((pair.relative() - (-e * vn) * pair.n).norm(), 1e-12);
    }
  }
}

TYPED_TEST(ContactImpulse, SlidingFrictionIsOnTheConeAgainstSlip) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(15);
  const double mu = 0.2;
  for (double e : {0.0, 0.5}) {
    for (int trial = 0; trial < 10; ++trial) {
      Pair<d> pair = randomApproachingPair<d>(rng);
      // Slip much faster than the approach: the sticking impulse leaves the cone.
      Vec<d> slipDirection = tangential<d>(randomVec<d>(rng), pair.n).normalized();
      pair.a.v += 5 * slipDirection;
      const Vec<d> before = pair.relative();
      const Vec<d> slip = tangential<d>(before, pair.n);
      const double vn = before.dot(pair.n);
      ImpulseSettings s;
      s.restitution = e;
      s.friction = mu;
      const Vec<d> j = pointImpulse<d>(pair.k(), before, pair.n, s);
      const double jn = j.dot(pair.n);
      const Vec<d> jt = tangential<d>(j, pair.n);
      EXPECT_GT(jn, 0.0);
      EXPECT_NEAR(jt.norm(), mu * jn, 1e-12 * jn);
      EXPECT_NEAR(jt.normalized().dot(slip.normalized()), -1.0, 1e-12);  // opposite to slip
      pair.apply(j);
      EXPECT_NEAR(pair.relative().dot(pair.n), -e * vn, 1e-12);
    }
  }
}

TYPED_TEST(ContactImpulse, SeparatingPairGetsNothing) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(16);
  Pair<d> pair = randomApproachingPair<d>(rng);
  pair.a.v += 1.5 * pair.n;  // normal relative velocity now +0.5
  ASSERT_GT(pair.relative().dot(pair.n), 0.0);
  ImpulseSettings s;
  s.restitution = 0.5;
  s.friction = 0.5;
  EXPECT_EQ(pointImpulse<d>(pair.k(), pair.relative(), pair.n, s), Vec<d>::Zero());
  pair.a.v -= 0.5 * pair.n;  // tangential up to rounding: nothing but rounding noise
  EXPECT_LT(pointImpulse<d>(pair.k(), pair.relative(), pair.n, s).norm(), 1e-14);
}

TYPED_TEST(ContactImpulse, StaticPartner) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(17);
  for (const double mu : {0.0, 0.3, 1e3}) {
    Pair<d> pair = randomApproachingPair<d>(rng);
    pair.b.infinite = true;
    pair.b.v.setZero();
    pair.b.w.setZero();
    makeApproaching(pair);
    const Mat<d> k = pair.k();
    EXPECT_LT((k - impulseFactor<d>(pair.a.at(pair.p))).norm(), 1e-15);
    const double vn = pair.relative().dot(pair.n);
    ImpulseSettings s;
    s.restitution = 0.3;
    s.friction = mu;
    const Vec<d> j = pointImpulse<d>(k, pair.relative(), pair.n, s);
    pair.apply(j);
    EXPECT_NEAR(pair.relative().dot(pair.n), -0.3 * vn, 1e-12);
    EXPECT_EQ(pair.b.v, Vec<d>::Zero());
    if (mu > 100) {
      EXPECT_LT(tangential<d>(pair.relative(), pair.n).norm(), 1e-12);
    }
  }
}

TYPED_TEST(ContactImpulse, FrictionMagnitudeClampNeverCreatesSliding) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(18);
  int clampedTrials = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Pair<d> pair = randomApproachingPair<d>(rng);
    pair.a.w *= 4;  // fast spin: the slip direction and K's coupling disagree more often
    makeApproaching(pair);
    const Vec<d> before = pair.relative();
    const double vn = before.dot(pair.n);
    ImpulseSettings s;
    s.restitution = 0.8;
    s.friction = 0.4;
    const Vec<d> free = pointImpulse<d>(pair.k(), before, pair.n, s);
    s.clampFrictionMagnitude = true;
    const Vec<d> j = pointImpulse<d>(pair.k(), before, pair.n, s);
    Pair<d> unclamped = pair;
    unclamped.apply(free);
    pair.apply(j);
    const double oldSlip = tangential<d>(before, pair.n).norm();
    if (tangential<d>(unclamped.relative(), pair.n).norm() > oldSlip * (1 + 1e-9)) ++clampedTrials;
    EXPECT_LE(tangential<d>(pair.relative(), pair.n).norm(), oldSlip * (1 + 1e-12) + 1e-14);
    EXPECT_NEAR(pair.relative().dot(pair.n), -0.8 * vn, 1e-12);
  }
  EXPECT_GT(clampedTrials, 0);  // the clamp was exercised
  // e = 0: the clamp is off by definition (notes 1.5), so the result equals the unclamped one.
  const Pair<d> pair = randomApproachingPair<d>(rng);
  ImpulseSettings s;
  s.friction = 0.4;
  const Vec<d> free = pointImpulse<d>(pair.k(), pair.relative(), pair.n, s);
  s.clampFrictionMagnitude = true;
  EXPECT_EQ(pointImpulse<d>(pair.k(), pair.relative(), pair.n, s), free);
}

// Large friction coupled through K can make n.K(n - mu t) <= 0: no sliding impulse reaches the
// target normal velocity. The impulse is then the frictionless one (no energy from friction).
TEST(ContactImpulse3D, SlidingWithoutSolutionFallsBackToFrictionless) {
  std::mt19937 rng(19);
  int found = 0;
  for (int trial = 0; trial < 10000 && found < 5; ++trial) {
    Pair<3> pair = randomApproachingPair<3>(rng);
    pair.b.infinite = true;
    pair.a.inertia = pair.a.inertia / 20;  // light in rotation: strong coupling in K
    pair.a.v += 2 * tangential<3>(randomVec<3>(rng), pair.n);
    makeApproaching(pair);
    const Mat<3> k = pair.k();
    const Vec<3> v = pair.relative();
    const Vec<3> t = tangential<3>(v, pair.n).normalized();
    const double mu = 2.5;
    const Vec<3> stick = k.inverse() * (-0.5 * v.dot(pair.n) * pair.n - v);  // e = 0.5
    const bool slides = tangential<3>(stick, pair.n).norm() > mu * stick.dot(pair.n);
    if (!slides || pair.n.dot(k * (pair.n - mu * t)) > 0) continue;
    ++found;
    ImpulseSettings s;
    s.restitution = 0.5;
    const Vec<3> frictionless = pointImpulse<3>(k, v, pair.n, s);
    s.friction = mu;
    const Vec<3> j = pointImpulse<3>(k, v, pair.n, s);
    EXPECT_LT((j - frictionless).norm(), 1e-14 * frictionless.norm());
    pair.apply(j);
    EXPECT_NEAR(pair.relative().dot(pair.n), -0.5 * v.dot(pair.n), 1e-12);
  }
  EXPECT_EQ(found, 5);
}

}  // namespace
