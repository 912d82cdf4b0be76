// Tests for the energy clamp of thesis Sec. 2.3.2: the kinetic energy of the reference state,
// measured by applying the scaled impulse to explicit bodies, never rises.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <random>
#include <type_traits>

#include "support/random_rigid.h"
#include "solvers/contact/energy_clamp.h"

namespace {

using namespace monolith::solvers::contact;
using Case = ClampResult::Case;

using monolith::test::randomVec;

template <int d>
AngMat<d> randomInverseInertia(std::mt19937& rng) {
  return monolith::test::randomInertiaLike<d>(rng, 0.5, 2.0);
}

template <int d>
ClampBody<d> randomBody(std::mt19937& rng) {
  std::uniform_real_distribution<double> m(0.3, 3.0);
  ClampBody<d> b;
  b.inverseMass = m(rng);
  b.inverseInertia = randomInverseInertia<d>(rng);
  b.velocity = randomVec<d>(rng);
  b.angularMomentum = AngVec<d>(randomVec<kAngularDim<d>>(rng));
  b.r = randomVec<d>(rng);
  return b;
}

// KE = 1/2 p m^{-1} p + 1/2 L I^{-1} L of the finite bodies, after linear impulse j at the
// lever arm (angular impulse r x j + torque).
template <int d>
double kineticEnergy(const ClampBody<d>& b, const Vec<d>& j = Vec<d>::Zero(),
                     const AngVec<d>& torque = AngVec<d>::Zero()) {
  if (b.inverseMass == 0) return 0;
  const Vec<d> v = b.velocity + b.inverseMass * j;
  const AngVec<d> l = b.angularMomentum + cross<d>(b.r, j) + torque;
  return 0.5 * v.squaredNorm() / b.inverseMass + 0.5 * l.dot(b.inverseInertia * l);
}

template <int d>
double energyAfter(const ClampBody<d>& a, const ClampBody<d>& b, const Vec<d>& j,
                   const AngVec<d>& torque, double scale) {
  return kineticEnergy<d>(a, Vec<d>(scale * j), AngVec<d>(scale * torque)) +
         kineticEnergy<d>(b, Vec<d>(-scale * j), AngVec<d>(-scale * torque));
}

template <int d>
double energyBefore(const ClampBody<d>& a, const ClampBody<d>& b) {
  return kineticEnergy<d>(a) + kineticEnergy<d>(b);
}

// The frictionless impulse along n that reverses the normal relative velocity at the contact
// (elastic): j = -2 v_n / (n.K n) n, with v_rel from the reference state itself.
template <int d>
Vec<d> elasticImpulse(const ClampBody<d>& a, const ClampBody<d>& b, const Vec<d>& n) {
  auto pointVelocity = [](const ClampBody<d>& body) {
    return Vec<d>(body.velocity +
                  angularCross<d>(AngVec<d>(body.inverseInertia * body.angularMomentum), body.r));
  };
  auto factor = [](const ClampBody<d>& body) {
    const CrossMat<d> rs = crossMatrix<d>(body.r);
    return Mat<d>(body.inverseMass * Mat<d>::Identity() +
                  rs.transpose() * body.inverseInertia * rs);
  };
  const double vn = (pointVelocity(a) - pointVelocity(b)).dot(n);
  return (-2 * vn / n.dot((factor(a) + factor(b)) * n)) * n;
}

template <typename T>
class EnergyClamp : public ::testing::Test {};
using Dimensions = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(EnergyClamp, Dimensions);

// A non-split pair approaching along n; elastic impulses are exactly energy-neutral.
template <int d>
void approachingPair(std::mt19937& rng, ClampBody<d>& a, ClampBody<d>& b, Vec<d>& n) {
  a = randomBody<d>(rng);
  b = randomBody<d>(rng);
  n = randomVec<d>(rng).normalized();
  const Vec<d> j = elasticImpulse<d>(a, b, n);
  if (j.dot(n) < 0) n = -n;  // make the pair approach along n (A receives +j along n)
}

TYPED_TEST(EnergyClamp, ImpulseThatRemovesEnergyIsKept) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(21);
  for (int trial = 0; trial < 20; ++trial) {
    ClampBody<d> a, b;
    Vec<d> n;
    approachingPair<d>(rng, a, b, n);
    for (double fraction : {0.5, 0.75}) {  // restitution 0 and 0.5: (1+e)/2 of the elastic one
      const Vec<d> j = fraction * elasticImpulse<d>(a, b, n);
      const ClampResult r = clampImpulseEnergy<d>(a, b, j);
      EXPECT_EQ(r.kind, Case::NoGain);
      EXPECT_EQ(r.scale, 1.0);
      const double before = energyBefore<d>(a, b);
      const double after = energyAfter<d>(a, b, j, AngVec<d>::Zero(), 1);
      EXPECT_LT(after, before);
      EXPECT_NEAR(r.energyChange, after - before, 1e-12 * before);
    }
  }
}

TYPED_TEST(EnergyClamp, EnergyAddingImpulseIsScaledToNeutral) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(22);
  for (int trial = 0; trial < 20; ++trial) {
    ClampBody<d> a, b;
    Vec<d> n;
    approachingPair<d>(rng, a, b, n);
    // 1.6 times the elastic impulse: KE(s) - KE = 0 at s = 1/1.6.
    const Vec<d> j = 1.6 * elasticImpulse<d>(a, b, n);
    const ClampResult r = clampImpulseEnergy<d>(a, b, j);
    EXPECT_EQ(r.kind, Case::Scaled);
    EXPECT_NEAR(r.scale, 1 / 1.6, 1e-12);
    const double before = energyBefore<d>(a, b);
    EXPECT_NEAR(energyAfter<d>(a, b, j, AngVec<d>::Zero(), r.scale), before, 1e-12 * before);
    EXPECT_NEAR(r.energyChange, 0.0, 1e-12 * before);
  }
}

TYPED_TEST(EnergyClamp, InfeasibleSplitStateDirectionIsDiscarded) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(23);
  for (int trial = 0; trial < 20; ++trial) {
    ClampBody<d> a = randomBody<d>(rng);
    ClampBody<d> b = randomBody<d>(rng);
    // Split state: the impulse was computed where the pair approached along n, but in the
    // reference state the bodies separate along n, so any push along n adds energy.
    const Vec<d> n = randomVec<d>(rng).normalized();
    a.r.setZero();
    b.r.setZero();
    a.velocity = n;
    b.velocity = -n;
    const Vec<d> j = 0.7 * n;
    const ClampResult r = clampImpulseEnergy<d>(a, b, j);
    EXPECT_EQ(r.kind, Case::Discarded);
    EXPECT_EQ(r.scale, 0.0);
    EXPECT_EQ(r.energyChange, 0.0);
    // Indeed every small multiple adds energy.
    EXPECT_GT(energyAfter<d>(a, b, j, AngVec<d>::Zero(), 1e-3), energyBefore<d>(a, b));
  }
}

TYPED_TEST(EnergyClamp, StaticPartnerTermsVanish) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(24);
  for (int trial = 0; trial < 20; ++trial) {
    ClampBody<d> a = randomBody<d>(rng);
    ClampBody<d> ground;  // infinite mass: inverse mass and inertia 0
    const Vec<d> j = randomVec<d>(rng);
    const ClampResult reference = clampImpulseEnergy<d>(a, ground, j);
    // Whatever velocity or momentum the static body carries, it contributes nothing.
    ground.velocity = randomVec<d>(rng, 10);
    ground.angularMomentum = AngVec<d>(randomVec<kAngularDim<d>>(rng, 10));
    ground.r = randomVec<d>(rng, 10);
    const ClampResult r = clampImpulseEnergy<d>(a, ground, j);
    EXPECT_EQ(r.scale, reference.scale);
    EXPECT_EQ(r.kind, reference.kind);
    const double before = kineticEnergy<d>(a);
    const double after = kineticEnergy<d>(a, Vec<d>(r.scale * j));
    EXPECT_LE(after, before * (1 + 1e-12));
    EXPECT_NEAR(r.energyChange, after - before, 1e-12 * (before + 1));
  }
  // Both infinite: nothing can change, the impulse passes unscaled.
  const ClampResult none = clampImpulseEnergy<d>(ClampBody<d>(), ClampBody<d>(), Vec<d>::Ones());
  EXPECT_EQ(none.kind, Case::NoGain);
  EXPECT_EQ(none.scale, 1.0);
}

TYPED_TEST(EnergyClamp, KinematicPartnerKeepsTheMovingFrameEnergy) {
  constexpr int d = TypeParam::value;
  // An elevator (kinematic, infinite mass) rises with speed 2 along n; a box falls onto it with
  // absolute speed +1 along n, i.e. -1 relative to the floor. The restitution-0.5 impulse sends
  // it to +0.5 relative (+2.5 absolute).
  const Vec<d> n = Vec<d>::Unit(d - 1);
  const double m = 2.0;
  ClampBody<d> box;
  box.inverseMass = 1 / m;
  box.inverseInertia = AngMat<d>::Identity();
  const Vec<d> j = m * 1.5 * n;
  const ClampBody<d> elevator;  // infinite mass
  // Absolute frame: the impulse raises the box's absolute KE and would be thrown away, and the
  // box could never be lifted by the elevator.
  box.velocity = 1.0 * n;
  EXPECT_EQ(clampImpulseEnergy<d>(box, elevator, j).kind, Case::Discarded);
  // The moving frame (what the caller passes): the bounce loses energy there and is kept.
  box.velocity = -1.0 * n;
  const ClampResult r = clampImpulseEnergy<d>(box, elevator, j);
  EXPECT_EQ(r.kind, Case::NoGain);
  EXPECT_EQ(r.scale, 1.0);
  EXPECT_NEAR(r.energyChange, 0.5 * m * (0.25 - 1.0), 1e-14);
  // A too-strong bounce in the moving frame (relative +2) is scaled to relative speed 1.
  const ClampResult strong = clampImpulseEnergy<d>(box, elevator, Vec<d>(3 * m * n));
  EXPECT_EQ(strong.kind, Case::Scaled);
  EXPECT_NEAR(strong.scale, 2.0 / 3.0, 1e-14);
}

TYPED_TEST(EnergyClamp, PureTorqueEntersBothBodies) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(25);
  for (int trial = 0; trial < 50; ++trial) {
    const ClampBody<d> a = randomBody<d>(rng);
    const ClampBody<d> b = randomBody<d>(rng);
    const Vec<d> j = randomVec<d>(rng);
    const AngVec<d> torque = AngVec<d>(randomVec<kAngularDim<d>>(rng));
    const ClampResult r = clampImpulseEnergy<d>(a, b, j, torque);
    const double before = energyBefore<d>(a, b);
    const double after = energyAfter<d>(a, b, j, torque, r.scale);
    EXPECT_NEAR(r.energyChange, after - before, 1e-12 * before);
    EXPECT_LE(after, before * (1 + 1e-12));
  }
}

TYPED_TEST(EnergyClamp, RandomSplitStatesNeverGainEnergy) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> unit(0, 1);
  int counts[3] = {0, 0, 0};
  for (int trial = 0; trial < 1000; ++trial) {
    ClampBody<d> a = randomBody<d>(rng);
    ClampBody<d> b = randomBody<d>(rng);
    if (unit(rng) < 0.2) b = ClampBody<d>();  // static partner now and then
    // An impulse from some other (split) state: arbitrary direction and size.
    const Vec<d> j = randomVec<d>(rng, 3);
    const AngVec<d> torque =
        unit(rng) < 0.5 ? AngVec<d>::Zero() : AngVec<d>(randomVec<kAngularDim<d>>(rng));
    const ClampResult r = clampImpulseEnergy<d>(a, b, j, torque);
    ++counts[static_cast<int>(r.kind)];
    ASSERT_GE(r.scale, 0.0);
    ASSERT_LE(r.scale, 1.0);
    const double before = energyBefore<d>(a, b);
    const double after = energyAfter<d>(a, b, j, torque, r.scale);
    ASSERT_LE(after, before * (1 + 1e-12)) << "trial " << trial;
    ASSERT_NEAR(r.energyChange, after - before, 1e-12 * before);
  }
  // All three cases occur.
  EXPECT_GT(counts[0], 0);
  EXPECT_GT(counts[1], 0);
  EXPECT_GT(counts[2], 0);
}

}  // namespace
