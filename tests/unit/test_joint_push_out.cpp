// Several bodies pushed apart at once (solvers/contact/joint_push_out.h): closed-form cases and
// random problems against a brute-force solution of the same quadratic program.
#include "solvers/contact/joint_push_out.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace {

using namespace monolith::solvers::contact;

template <int d>
JointBody<d> body(double mass, double inertia) {
  JointBody<d> b;
  b.inverseMass = 1 / mass;
  b.inverseInertia = AngMat<d>::Identity() / inertia;
  return b;
}

template <int d>
JointPoint<d> point(int a, int b, const Vec<d>& ra, const Vec<d>& rb, const Vec<d>& n, double depth) {
  JointPoint<d> p;
  p.a = a;
  p.b = b;
  p.ra = ra;
  p.rb = rb;
  p.n = n;
  p.depth = depth;
  return p;
}

constexpr int kSweeps = 100000;
constexpr double kTight = 1e-12;

}  // namespace

TEST(JointPushOut, TwoBodiesShareTheOverlapInverselyToTheirMasses) {
  // Overlap 0.3 along x at a point on the line of the centres: no turn; the heavier moves less.
  const std::vector<JointBody<3>> bodies{body<3>(1, 1), body<3>(2, 1)};
  const std::vector<JointPoint<3>> points{point<3>(0, 1, Eigen::Vector3d(-0.5, 0, 0), Eigen::Vector3d(0.5, 0, 0),
                                                   Eigen::Vector3d::UnitX(), 0.3)};
  std::vector<JointMove<3>> moves;
  EXPECT_LT(solveJointPushOut<3>(bodies, points, kSweeps, 1e-15, moves), kTight);
  EXPECT_NEAR(moves[0].dx.x(), 0.2, kTight);  // 0.3 * 2 / 3
  EXPECT_NEAR(moves[1].dx.x(), -0.1, kTight);
  EXPECT_LT(moves[0].dtheta.norm() + moves[1].dtheta.norm(), kTight);
}

TEST(JointPushOut, AChainAgainstAWallMovesEachBodyOnlyAsFarAsItMust) {
  // Wall | A | B along x, A 0.1 into the wall and B 0.1 into A (1-D, points on the axis): A moves
  // 0.1, B 0.2, whatever their masses. One body at a time would push A back into the wall or
  // leave B in A.
  const std::vector<JointBody<2>> bodies{body<2>(5, 1), body<2>(0.1, 1)};
  const Eigen::Vector2d x = Eigen::Vector2d::UnitX();
  const std::vector<JointPoint<2>> points{point<2>(0, -1, -0.5 * x, Eigen::Vector2d::Zero(), x, 0.1),
                                          point<2>(1, 0, -0.5 * x, 0.5 * x, x, 0.1)};
  std::vector<JointMove<2>> moves;
  EXPECT_LT(solveJointPushOut<2>(bodies, points, kSweeps, 1e-15, moves), 1e-12);
  EXPECT_NEAR(moves[0].dx.x(), 0.1, 1e-12);
  EXPECT_NEAR(moves[1].dx.x(), 0.2, 1e-12);
}

TEST(JointPushOut, APointAlreadyApartOnlyStopsAnApproach) {
  // A (heavy) overlaps B (light) by 0.2 along x; B lies 0.05 from a fixed partner on its right.
  // Alone, B would take almost all of the 0.2; it gives way only up to the partner, and A moves
  // the rest.
  const std::vector<JointBody<2>> bodies{body<2>(1000, 1), body<2>(0.001, 1)};
  const Eigen::Vector2d x = Eigen::Vector2d::UnitX();
  const std::vector<JointPoint<2>> points{point<2>(1, 0, -0.5 * x, 0.5 * x, x, 0.2),  // B against A: n out of A
                                          point<2>(-1, 1, Eigen::Vector2d::Zero(), 0.5 * x, x, -0.05)};
  std::vector<JointMove<2>> moves;
  // Masses a millionfold apart: rounding on the scale of 1e-16 times that ratio.
  EXPECT_LT(solveJointPushOut<2>(bodies, points, kSweeps, 1e-15, moves), 1e-9);
  EXPECT_NEAR(moves[1].dx.x(), 0.05, 1e-9);
  EXPECT_NEAR(moves[0].dx.x(), -0.15, 1e-9);
}

TEST(JointPushOut, AChainTooLongForTheExactSolveIsSolvedBySweeps) {
  // Wall | A_0 | ... | A_99 along x, each 1 cm into the one before (100 points: beyond the exact
  // solve's 96, so Gauss-Seidel sweeps): A_i moves (i + 1) cm, as little as the chain allows.
  std::vector<JointBody<2>> bodies;
  std::vector<JointPoint<2>> points;
  const Eigen::Vector2d x = Eigen::Vector2d::UnitX();
  for (int i = 0; i < 100; ++i) {
    bodies.push_back(body<2>(1, 1));
    points.push_back(point<2>(i, i - 1, -0.5 * x, i == 0 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(0.5 * x), x, 0.01));
  }
  std::vector<JointMove<2>> moves;
  EXPECT_LT(solveJointPushOut<2>(bodies, points, kSweeps, 1e-15, moves), 1e-9);
  for (int i = 0; i < 100; ++i) EXPECT_NEAR(moves[i].dx.x(), 0.01 * (i + 1), 1e-9) << i;
}

namespace {

// The same program solved by brute force: every subset of the points taken as tight, its
// multipliers from the normal equations, kept if they are >= 0 and every point is satisfied;
// the least objective wins.
template <int d>
double bruteForceObjective(const std::vector<JointBody<d>>& bodies, const std::vector<JointPoint<d>>& points) {
  constexpr int A = kAngularDim<d>, D = d + A;
  const int nb = static_cast<int>(bodies.size()), m = static_cast<int>(points.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(m, D * nb), Minv = Eigen::MatrixXd::Zero(D * nb, D * nb);
  for (int i = 0; i < nb; ++i) {
    Minv.block(D * i, D * i, d, d) = bodies[i].inverseMass * Eigen::MatrixXd::Identity(d, d);
    Minv.block(D * i + d, D * i + d, A, A) = bodies[i].inverseInertia;
  }
  Eigen::VectorXd depth(m);
  for (int k = 0; k < m; ++k) {
    const JointPoint<d>& p = points[k];
    depth[k] = p.depth;
    if (p.a >= 0) {
      J.block(k, D * p.a, 1, d) = p.n.transpose();
      J.block(k, D * p.a + d, 1, A) = cross<d>(p.ra, p.n).transpose();
    }
    if (p.b >= 0) {
      J.block(k, D * p.b, 1, d) = -p.n.transpose();
      J.block(k, D * p.b + d, 1, A) = -cross<d>(p.rb, p.n).transpose();
    }
  }
  Eigen::MatrixXd M = Minv.inverse();
  double best = std::numeric_limits<double>::infinity();
  for (int subset = 0; subset < (1 << m); ++subset) {
    std::vector<int> tight;
    for (int k = 0; k < m; ++k)
      if (subset & (1 << k)) tight.push_back(k);
    Eigen::VectorXd move = Eigen::VectorXd::Zero(D * nb);
    if (!tight.empty()) {
      Eigen::MatrixXd Js(tight.size(), D * nb);
      Eigen::VectorXd ds(tight.size());
      for (std::size_t r = 0; r < tight.size(); ++r) Js.row(r) = J.row(tight[r]), ds[r] = depth[tight[r]];
      const Eigen::MatrixXd K = Js * Minv * Js.transpose();
      Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
      if (lu.rank() < static_cast<int>(tight.size())) continue;
      const Eigen::VectorXd lambda = lu.solve(ds);
      if ((lambda.array() < -1e-12).any()) continue;
      move = Minv * Js.transpose() * lambda;
    }
    if (((J * move - depth).array() < -1e-9).any()) continue;
    best = std::min(best, move.dot(M * move));
  }
  return best;
}

template <int d>
double objective(const std::vector<JointBody<d>>& bodies, const std::vector<JointMove<d>>& moves) {
  double sum = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    sum += moves[i].dx.squaredNorm() / bodies[i].inverseMass +
           moves[i].dtheta.dot(bodies[i].inverseInertia.inverse() * moves[i].dtheta);
  return sum;
}

template <int d>
void randomProblemsMatchTheBruteForceSolution(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), positive(0.05, 1);
  std::uniform_int_distribution<int> pick(-1, 2);
  auto randomVec = [&] {
    Vec<d> v;
    for (int i = 0; i < d; ++i) v[i] = u(rng);
    return v;
  };
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<JointBody<d>> bodies;
    for (int i = 0; i < 3; ++i) {
      JointBody<d> b;
      b.inverseMass = 1 / std::exp(3 * u(rng));  // masses over e^+-3
      AngMat<d> R;
      for (int r = 0; r < R.rows(); ++r)
        for (int c = 0; c < R.cols(); ++c) R(r, c) = u(rng);
      b.inverseInertia = (R * R.transpose() + 0.1 * AngMat<d>::Identity()) / std::exp(3 * u(rng));
      bodies.push_back(b);
    }
    std::vector<JointPoint<d>> points;
    const int m = 2 + trial % 4;  // 2-5 points
    for (int k = 0; k < m; ++k) {
      int a = pick(rng), b = pick(rng);
      if (a < 0 && b < 0) a = 0;
      if (a == b) b = -1;
      const Vec<d> n = randomVec().normalized();
      points.push_back(point<d>(a, b, randomVec(), randomVec(), n, positive(rng) * (k % 3 == 2 ? -0.2 : 1)));
    }
    const double expected = bruteForceObjective<d>(bodies, points);
    if (!std::isfinite(expected)) continue;  // infeasible
    std::vector<JointMove<d>> moves;
    const double left = solveJointPushOut<d>(bodies, points, kSweeps, 1e-14, moves);
    EXPECT_LT(left, 1e-8) << "trial " << trial;
    EXPECT_NEAR(objective<d>(bodies, moves), expected, 1e-6 * (1 + expected)) << "trial " << trial;
    ++compared;
  }
  EXPECT_GT(compared, 100);
}

}  // namespace

TEST(JointPushOut, RandomProblemsMatchTheBruteForceSolutionIn3D) { randomProblemsMatchTheBruteForceSolution<3>(7); }

TEST(JointPushOut, RandomProblemsMatchTheBruteForceSolutionIn2D) { randomProblemsMatchTheBruteForceSolution<2>(11); }
