// Tests for the central-body push-out of thesis Sec. 4.6.1 / Appendix B against a brute-force
// reference: static bodies become finite bodies of mass m/eps and inertia I/eps, and the full
// dense system (B.1) is solved for every j_o at once. As eps -> 0 it must converge to the
// special-case solves of B.3.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <limits>
#include <random>
#include <type_traits>

#include "support/random_rigid.h"
#include "solvers/contact/push_out.h"

namespace {

using namespace monolith::solvers::contact;

using monolith::test::randomVec;

template <int d>
AngMat<d> randomInertia(std::mt19937& rng) {
  return monolith::test::randomInertiaLike<d>(rng, 0.3, 2.0);
}

template <int d>
PushOutCentral<d> randomCentral(std::mt19937& rng, bool isStatic = false) {
  std::uniform_real_distribution<double> m(0.5, 3.0);
  PushOutCentral<d> c;
  c.isStatic = isStatic;
  c.mass = m(rng);
  c.inertia = randomInertia<d>(rng);
  return c;
}

template <int d>
PushOutOuter<d> randomOuter(std::mt19937& rng, bool isStatic = false) {
  std::uniform_real_distribution<double> m(0.5, 3.0);
  PushOutOuter<d> o;
  o.isStatic = isStatic;
  o.r = randomVec<d>(rng);
  o.q = randomVec<d>(rng);
  o.mass = m(rng);
  o.inertia = randomInertia<d>(rng);
  o.displacement = randomVec<d>(rng, 0.1);
  return o;
}

// K = m^{-1} delta + q*^T I^{-1} q*, written out independently of the solver.
template <int d>
Mat<d> factor(double mass, const AngMat<d>& inertia, const Vec<d>& q) {
  const CrossMat<d> qs = crossMatrix<d>(q);
  return Mat<d>(Mat<d>::Identity() / mass + qs.transpose() * inertia.inverse() * qs);
}

template <int d>
struct Reference {
  Vec<d> dv;
  AngVec<d> dw;
  std::vector<Vec<d>> j;  // every outer's impulse, statics included (zero if not taking part)
};

// The dense system (B.1) for all j_o, with statics (and a static centre) of mass m/eps. With a
// static centre, static outers take no part (B.3: they could not exchange anything).
template <int d>
Reference<d> bruteForce(const PushOutCentral<d>& c, const std::vector<PushOutOuter<d>>& outers,
                        double eps) {
  const double mc = c.isStatic ? c.mass / eps : c.mass;
  const AngMat<d> icInv = (c.isStatic ? AngMat<d>(c.inertia / eps) : c.inertia).inverse();
  std::vector<int> active;
  for (int i = 0; i < static_cast<int>(outers.size()); ++i) {
    if (!(c.isStatic && outers[i].isStatic)) active.push_back(i);
  }
  const int n = static_cast<int>(active.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n * d, n * d);
  Eigen::VectorXd b(n * d);
  for (int row = 0; row < n; ++row) {
    const PushOutOuter<d>& o = outers[active[row]];
    const double scale = o.isStatic ? 1 / eps : 1;
    for (int col = 0; col < n; ++col) {
      const PushOutOuter<d>& p = outers[active[col]];
      // m_c^{-1} j + r_o*^T I_c^{-1} j_tau with j = -sum j_p, j_tau = -sum r_p* j_p.
      Mat<d> block =
          -Mat<d>::Identity() / mc - crossMatrix<d>(o.r).transpose() * icInv * crossMatrix<d>(p.r);
      if (row == col) block -= factor<d>(o.mass * scale, AngMat<d>(o.inertia * scale), o.q);
      a.block<d, d>(row * d, col * d) = block;
    }
    b.segment<d>(row * d) = o.displacement;
  }
  const Eigen::VectorXd solution = a.fullPivLu().solve(b);
  Reference<d> ref;
  ref.j.assign(outers.size(), Vec<d>::Zero());
  Vec<d> j = Vec<d>::Zero();
  AngVec<d> jTau = AngVec<d>::Zero();
  for (int row = 0; row < n; ++row) {
    const Vec<d> jo = solution.segment<d>(row * d);
    ref.j[active[row]] = jo;
    j -= jo;
    jTau -= cross<d>(outers[active[row]].r, jo);
  }
  ref.dv = j / mc;
  ref.dw = icInv * jTau;
  return ref;
}

template <typename A, typename B>
void expectClose(const A& value, const B& expected, double tolerance, const char* what) {
  EXPECT_LE((value - expected).norm(), tolerance * (1 + expected.norm()))
      << what << ": " << value.transpose() << " vs " << expected.transpose();
}

// The solver agrees with the brute force at eps = 1e-7 and 1e-8, and the static bodies' net
// impulse implied by momentum balance (m_c dv = -sum j_o) equals the brute force's.
template <int d>
void checkAgainstBruteForce(const PushOutCentral<d>& c, const std::vector<PushOutOuter<d>>& outers,
                            const PushOutResult<d>& result) {
  for (double eps : {1e-7, 1e-8}) {
    const Reference<d> ref = bruteForce<d>(c, outers, eps);
    if (!c.isStatic) {
      expectClose(result.centralDisplacement, ref.dv, 1e-5, "dv");
      expectClose(result.centralRotation, ref.dw, 1e-5, "dw");
    } else {
      EXPECT_EQ(result.centralDisplacement, Vec<d>::Zero());
      EXPECT_EQ(result.centralRotation, AngVec<d>::Zero());
    }
    Vec<d> staticsLinear = Vec<d>::Zero();
    AngVec<d> staticsAngular = AngVec<d>::Zero();
    Vec<d> refStaticsLinear = Vec<d>::Zero();
    AngVec<d> refStaticsAngular = AngVec<d>::Zero();
    if (!c.isStatic) {
      // The statics' share of c's momentum change: m_c dv + sum_d j_d, I_c dw + sum_d r_d x j_d.
      staticsLinear = -c.mass * result.centralDisplacement;
      staticsAngular = -c.inertia * result.centralRotation;
    }
    for (std::size_t i = 0; i < outers.size(); ++i) {
      if (outers[i].isStatic) {
        EXPECT_EQ(result.outerImpulses[i], Vec<d>::Zero());
        EXPECT_EQ(result.outerDisplacements[i], Vec<d>::Zero());
        EXPECT_EQ(result.outerRotations[i], AngVec<d>::Zero());
        refStaticsLinear += ref.j[i];
        refStaticsAngular += cross<d>(outers[i].r, ref.j[i]);
        continue;
      }
      expectClose(result.outerImpulses[i], ref.j[i], 1e-5, "j_o");
      if (!c.isStatic) {
        staticsLinear -= result.outerImpulses[i];
        staticsAngular -= cross<d>(outers[i].r, result.outerImpulses[i]);
      }
    }
    if (!c.isStatic) {
      expectClose(staticsLinear, refStaticsLinear, 1e-5, "static linear impulse");
      expectClose(staticsAngular, refStaticsAngular, 1e-5, "static angular impulse");
    }
  }
}

// Displacement of c at p_o minus that of o at p_o (rigid motions of both, dtau = 1).
template <int d>
Vec<d> relativeDisplacement(const PushOutResult<d>& r, const PushOutOuter<d>& o, std::size_t i) {
  const Vec<d> central = r.centralDisplacement + angularCross<d>(r.centralRotation, o.r);
  const Vec<d> outer = r.outerDisplacements[i] + angularCross<d>(r.outerRotations[i], o.q);
  return central - outer;
}

// Every outer's overlap is removed exactly ((B.1) residual zero) and, with all impulses known,
// the central body's momentum change balances them.
template <int d>
void checkExactlySolved(const PushOutCentral<d>& c, const std::vector<PushOutOuter<d>>& outers,
                        const PushOutResult<d>& r) {
  Vec<d> linear = Vec<d>::Zero();
  AngVec<d> angular = AngVec<d>::Zero();
  for (std::size_t i = 0; i < outers.size(); ++i) {
    if (c.isStatic && outers[i].isStatic) continue;
    expectClose(relativeDisplacement<d>(r, outers[i], i), outers[i].displacement, 1e-12,
                "(B.1) residual");
    // The outer's motion is that of the impulse: m_o^{-1} j_o and I_o^{-1}(q_o x j_o).
    if (!outers[i].isStatic) {
      expectClose(r.outerDisplacements[i], Vec<d>(r.outerImpulses[i] / outers[i].mass), 1e-14,
                  "dx_o");
      expectClose(
          r.outerRotations[i],
          AngVec<d>(outers[i].inertia.inverse() * cross<d>(outers[i].q, r.outerImpulses[i])), 1e-13,
          "dw_o");
    }
    linear -= r.outerImpulses[i];
    angular -= cross<d>(outers[i].r, r.outerImpulses[i]);
  }
  bool anyStatic = false;
  for (const auto& o : outers) anyStatic = anyStatic || o.isStatic;
  if (!c.isStatic && !anyStatic) {
    expectClose(Vec<d>(c.mass * r.centralDisplacement), linear, 1e-12, "linear momentum");
    expectClose(AngVec<d>(c.inertia * r.centralRotation), angular, 1e-12, "angular momentum");
  }
}

template <typename T>
class PushOut : public ::testing::Test {};
using Dimensions = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(PushOut, Dimensions);

TYPED_TEST(PushOut, AllDynamic) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(31);
  for (int count : {1, 2, 3}) {
    for (int trial = 0; trial < 5; ++trial) {
      const PushOutCentral<d> c = randomCentral<d>(rng);
      std::vector<PushOutOuter<d>> outers;
      for (int i = 0; i < count; ++i) outers.push_back(randomOuter<d>(rng));
      const PushOutResult<d> r = solvePushOut<d>(c, outers);
      EXPECT_EQ(r.kind, PushOutCase::AllDynamic);
      checkExactlySolved<d>(c, outers, r);
      checkAgainstBruteForce<d>(c, outers, r);
    }
  }
}

TYPED_TEST(PushOut, CentralStatic) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(32);
  for (int trial = 0; trial < 5; ++trial) {
    const PushOutCentral<d> c = randomCentral<d>(rng, true);
    std::vector<PushOutOuter<d>> outers = {randomOuter<d>(rng), randomOuter<d>(rng, true),
                                           randomOuter<d>(rng)};
    const PushOutResult<d> r = solvePushOut<d>(c, outers);
    EXPECT_EQ(r.kind, PushOutCase::CentralStatic);
    checkExactlySolved<d>(c, outers, r);
    checkAgainstBruteForce<d>(c, outers, r);
    // j_d = -K_d^{-1} v_d.
    for (std::size_t i : {0u, 2u}) {
      const Mat<d> k = factor<d>(outers[i].mass, outers[i].inertia, outers[i].q);
      expectClose(Vec<d>(k * r.outerImpulses[i]), Vec<d>(-outers[i].displacement), 1e-13, "K j_d");
    }
  }
}

TYPED_TEST(PushOut, OneStaticWithDynamics) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(33);
  for (int dynamics : {0, 1, 2}) {
    for (int trial = 0; trial < 5; ++trial) {
      const PushOutCentral<d> c = randomCentral<d>(rng);
      std::vector<PushOutOuter<d>> outers;
      for (int i = 0; i < dynamics; ++i) outers.push_back(randomOuter<d>(rng));
      outers.insert(outers.begin() + (trial % (dynamics + 1)), randomOuter<d>(rng, true));
      const PushOutResult<d> r = solvePushOut<d>(c, outers);
      EXPECT_EQ(r.kind, PushOutCase::OneStatic);
      checkExactlySolved<d>(c, outers, r);  // includes B.4 at the static contact
      checkAgainstBruteForce<d>(c, outers, r);
    }
  }
}

TYPED_TEST(PushOut, CoincidentStatics) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(34);
  for (int trial = 0; trial < 5; ++trial) {
    const PushOutCentral<d> c = randomCentral<d>(rng);
    std::vector<PushOutOuter<d>> outers = {randomOuter<d>(rng, true), randomOuter<d>(rng),
                                           randomOuter<d>(rng, true), randomOuter<d>(rng, true)};
    outers[2].r = outers[0].r;
    outers[3].r = outers[0].r;
    const PushOutResult<d> r = solvePushOut<d>(c, outers);
    EXPECT_EQ(r.kind, PushOutCase::OneStatic);
    checkAgainstBruteForce<d>(c, outers, r);
    // The dynamic outer is still resolved exactly.
    expectClose(relativeDisplacement<d>(r, outers[1], 1), outers[1].displacement, 1e-12, "dynamic");
  }
}

TYPED_TEST(PushOut, GeneralStatics) {
  constexpr int d = TypeParam::value;
  std::mt19937 rng(35);
  for (int trial = 0; trial < 5; ++trial) {
    const PushOutCentral<d> c = randomCentral<d>(rng);
    std::vector<PushOutOuter<d>> outers = {randomOuter<d>(rng, true), randomOuter<d>(rng, true),
                                           randomOuter<d>(rng), randomOuter<d>(rng, true)};
    // Spread-out, non-collinear static points (in 2-D, two distinct points already suffice).
    outers[0].r = Vec<d>::Unit(0) + randomVec<d>(rng, 0.1);
    outers[1].r = Vec<d>::Unit(1) + randomVec<d>(rng, 0.1);
    outers[3].r = -Vec<d>::Unit(d - 1) + randomVec<d>(rng, 0.1);
    const PushOutResult<d> r = solvePushOut<d>(c, outers);
    EXPECT_EQ(r.kind, PushOutCase::StaticsGeneral);
    checkAgainstBruteForce<d>(c, outers, r);
    // The statics fix c alone: the dynamic outer does not change dv, dw.
    std::vector<PushOutOuter<d>> staticsOnly = {outers[0], outers[1], outers[3]};
    const PushOutResult<d> alone = solvePushOut<d>(c, staticsOnly);
    expectClose(alone.centralDisplacement, r.centralDisplacement, 1e-13, "dv without dynamics");
    expectClose(alone.centralRotation, r.centralRotation, 1e-13, "dw without dynamics");
    expectClose(relativeDisplacement<d>(r, outers[2], 2), outers[2].displacement, 1e-12, "dynamic");
  }
  {
    // A static given with infinite mass weighs its contact with K_hat_s = identity, as a static
    // of unit mass with its contact at its centre would.
    const PushOutCentral<d> c = randomCentral<d>(rng);
    std::vector<PushOutOuter<d>> outers = {randomOuter<d>(rng, true), randomOuter<d>(rng, true),
                                           randomOuter<d>(rng, true), randomOuter<d>(rng)};
    outers[0].r = Vec<d>::Unit(0);
    outers[1].r = Vec<d>::Unit(1);
    outers[2].r = outers[1].r;
    std::vector<PushOutOuter<d>> unit = outers;
    outers[1].mass = std::numeric_limits<double>::infinity();
    unit[1].mass = 1;
    unit[1].q.setZero();
    const PushOutResult<d> r = solvePushOut<d>(c, outers);
    const PushOutResult<d> expected = solvePushOut<d>(c, unit);
    ASSERT_TRUE(r.centralDisplacement.allFinite());
    expectClose(r.centralDisplacement, expected.centralDisplacement, 1e-13, "dv");
    expectClose(r.centralRotation, expected.centralRotation, 1e-13, "dw");
  }
  if constexpr (d == 2) {
    // Two distinct static points are already the general case in 2-D.
    const PushOutCentral<d> c = randomCentral<d>(rng);
    std::vector<PushOutOuter<d>> outers = {randomOuter<d>(rng, true), randomOuter<d>(rng, true)};
    outers[0].r = Vec<d>(1, 0);
    outers[1].r = Vec<d>(-1, 0.2);
    const PushOutResult<d> r = solvePushOut<d>(c, outers);
    EXPECT_EQ(r.kind, PushOutCase::StaticsGeneral);
    checkAgainstBruteForce<d>(c, outers, r);
  }
}

TEST(PushOut3D, CollinearStatics) {
  std::mt19937 rng(36);
  for (int trial = 0; trial < 5; ++trial) {
    const PushOutCentral<3> c = randomCentral<3>(rng);
    std::vector<PushOutOuter<3>> outers = {randomOuter<3>(rng, true), randomOuter<3>(rng),
                                           randomOuter<3>(rng, true), randomOuter<3>(rng, true),
                                           randomOuter<3>(rng)};
    const Vec<3> centre = randomVec<3>(rng, 0.3);
    const Vec<3> u = randomVec<3>(rng).normalized();
    outers[0].r = centre - 0.8 * u;
    outers[2].r = centre + 0.3 * u;
    outers[3].r = centre + 0.9 * u;
    const PushOutResult<3> r = solvePushOut<3>(c, outers);
    EXPECT_EQ(r.kind, PushOutCase::StaticsCollinear);
    checkAgainstBruteForce<3>(c, outers, r);
    for (std::size_t i : {1u, 4u}) {
      expectClose(relativeDisplacement<3>(r, outers[i], i), outers[i].displacement, 1e-12,
                  "dynamic");
    }
  }
}

TEST(PushOut3D, NearlyCoincidentStaticsUseTheLengthScale) {
  std::mt19937 rng(37);
  PushOutCentral<3> c = randomCentral<3>(rng);
  std::vector<PushOutOuter<3>> outers = {randomOuter<3>(rng, true), randomOuter<3>(rng, true)};
  outers[1].r = outers[0].r + Vec<3>(0.05, 0, 0);  // scatter 0.05^2/2 < 0.01 L^2 for L = 1
  c.lengthScale = 1;
  EXPECT_EQ(solvePushOut<3>(c, outers).kind, PushOutCase::OneStatic);
  c.lengthScale = 0.1;  // now 0.00125 > 0.01 * 0.01: two distinct points on a line
  EXPECT_EQ(solvePushOut<3>(c, outers).kind, PushOutCase::StaticsCollinear);
}

// Physical sign check: a box sunk 0.1 into the static ground rises by 0.1; a ball sunk 0.1 into a
// static box is pushed up by 0.1 (d_o runs from c's surface point to o's surface point).
TYPED_TEST(PushOut, PushesApartInTheRightDirection) {
  constexpr int d = TypeParam::value;
  const Vec<d> up = Vec<d>::Unit(1);
  PushOutCentral<d> box;
  box.mass = 2;
  PushOutOuter<d> ground;
  ground.isStatic = true;
  ground.r = -up;                  // contact below the box's centre
  ground.displacement = 0.1 * up;  // box bottom (inside) -> ground surface: upwards
  const PushOutResult<d> rise = solvePushOut<d>(box, {ground});
  expectClose(rise.centralDisplacement, Vec<d>(0.1 * up), 1e-14, "box rises");
  expectClose(rise.centralRotation, AngVec<d>::Zero(), 1e-14, "no tilt");

  box.isStatic = true;
  PushOutOuter<d> ball;
  ball.r = up;         // contact on the box's top
  ball.q = -0.5 * up;  // below the ball's centre
  ball.mass = 3;
  ball.displacement = -0.1 * up;  // box top (inside the ball) -> ball bottom (inside the box)
  const PushOutResult<d> push = solvePushOut<d>(box, {ball});
  expectClose(push.outerDisplacements[0], Vec<d>(0.1 * up), 1e-14, "ball rises");
  expectClose(push.outerImpulses[0], Vec<d>(0.3 * up), 1e-14, "ball impulse");
}

TYPED_TEST(PushOut, AResultWrittenOverAnEarlierOneEqualsAFreshOne) {
  // Push-out solves into one kept result per thread: every case after every other, with more or
  // fewer outers, must give exactly what a fresh result gets (nothing stale: the central motion
  // of a static centre, the lists' lengths, an outer static now and dynamic before).
  constexpr int d = TypeParam::value;
  std::mt19937 rng(23);
  PushOutResult<d> kept;
  for (int trial = 0; trial < 60; ++trial) {
    const PushOutCentral<d> c = randomCentral<d>(rng, trial % 5 == 0);
    std::vector<PushOutOuter<d>> outers;
    const int count = 1 + trial % 4;
    for (int i = 0; i < count; ++i) outers.push_back(randomOuter<d>(rng, (trial + i) % 3 == 0));
    solvePushOut<d>(c, outers, kept);
    const PushOutResult<d> fresh = solvePushOut<d>(c, outers);
    EXPECT_EQ(kept.kind, fresh.kind) << trial;
    EXPECT_EQ(kept.centralDisplacement, fresh.centralDisplacement) << trial;
    EXPECT_EQ(kept.centralRotation, fresh.centralRotation) << trial;
    EXPECT_EQ(kept.outerImpulses, fresh.outerImpulses) << trial;
    EXPECT_EQ(kept.outerDisplacements, fresh.outerDisplacements) << trial;
    EXPECT_EQ(kept.outerRotations, fresh.outerRotations) << trial;
  }
}

}  // namespace
