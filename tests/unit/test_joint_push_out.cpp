// Several bodies pushed apart at once (solvers/contact/joint_push_out.h): closed-form cases and
// random problems against a brute-force solution of the same quadratic program.
#include "solvers/contact/joint_push_out.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

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

// Gauss-Seidel sweeps over all points in their order, stopped after the first sweep in which no
// point's separation changes by more than `tolerance`: the sweeps solveJointPushOut runs per
// connected component, written out over all points at once.
template <int d>
std::vector<JointMove<d>> sweepsOverAllPoints(const std::vector<JointBody<d>>& bodies,
                                              const std::vector<JointPoint<d>>& points, int sweeps, double tolerance) {
  std::vector<JointMove<d>> moves(bodies.size());
  std::vector<AngVec<d>> ca(points.size(), AngVec<d>::Zero()), cb(points.size(), AngVec<d>::Zero());
  std::vector<AngVec<d>> ia(points.size(), AngVec<d>::Zero()), ib(points.size(), AngVec<d>::Zero());
  std::vector<double> inverseMass(points.size(), 0.0), lambda(points.size(), 0.0);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const JointPoint<d>& p = points[k];
    double mass = 0;
    if (p.a >= 0) {
      ca[k] = cross<d>(p.ra, p.n);
      ia[k] = bodies[p.a].inverseInertia * ca[k];
      mass += bodies[p.a].inverseMass + ca[k].dot(ia[k]);
    }
    if (p.b >= 0) {
      cb[k] = cross<d>(p.rb, p.n);
      ib[k] = bodies[p.b].inverseInertia * cb[k];
      mass += bodies[p.b].inverseMass + cb[k].dot(ib[k]);
    }
    inverseMass[k] = mass > 0 ? 1 / mass : 0;
  }
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    double largest = 0;
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (!(inverseMass[k] > 0)) continue;
      const JointPoint<d>& p = points[k];
      double gained = 0;
      if (p.a >= 0) gained += p.n.dot(moves[p.a].dx) + ca[k].dot(moves[p.a].dtheta);
      if (p.b >= 0) gained -= p.n.dot(moves[p.b].dx) + cb[k].dot(moves[p.b].dtheta);
      const double next = std::max(0.0, lambda[k] + (p.depth - gained) * inverseMass[k]);
      const double change = next - lambda[k];
      if (change == 0) continue;
      largest = std::max(largest, std::abs(change) / inverseMass[k]);
      lambda[k] = next;
      if (p.a >= 0) {
        moves[p.a].dx += change * bodies[p.a].inverseMass * p.n;
        moves[p.a].dtheta += change * ia[k];
      }
      if (p.b >= 0) {
        moves[p.b].dx -= change * bodies[p.b].inverseMass * p.n;
        moves[p.b].dtheta -= change * ib[k];
      }
    }
    if (largest <= tolerance) break;
  }
  return moves;
}

}  // namespace

TEST(JointPushOut, SeparateJamsSweptAtOnceGiveTheSweepsOverAllPoints) {
  // Three jams that share no body, their points interleaved (130 points: Gauss-Seidel sweeps):
  // chains of 70, 45 and 15 bodies against walls, each link 1 cm deep and off the line of the
  // centres (so the bodies turn), with masses that differ along each chain, so that each jam
  // would stop after a different number of sweeps on its own. Swept per jam at once, the moves
  // must be bitwise those of the sweeps over all points, which stop only when every jam is
  // quiet, on one thread and on two.
  std::vector<JointBody<3>> bodies;
  std::vector<std::vector<JointPoint<3>>> chains(3);
  const int lengths[3] = {70, 45, 15};
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), off(0, 0.1, 0.05);
  for (int c = 0; c < 3; ++c) {
    const int first = static_cast<int>(bodies.size());
    for (int i = 0; i < lengths[c]; ++i) {
      bodies.push_back(body<3>(1 + (i % 5) * (c + 1), 0.5 + 0.1 * c));
      const int self = first + i, before = i == 0 ? -1 : self - 1;
      chains[c].push_back(point<3>(self, before, -0.5 * x + off, 0.5 * x + off, x, 0.01 * (1 + 0.3 * c)));
    }
  }
  std::vector<JointPoint<3>> points;
  for (std::size_t k = 0; k < 70; ++k)
    for (int c = 0; c < 3; ++c)
      if (k < chains[c].size()) points.push_back(chains[c][k]);
  const double tolerance = 1e-13;
  const int sweeps = 20000;
  const std::vector<JointMove<3>> reference = sweepsOverAllPoints<3>(bodies, points, sweeps, tolerance);
  for (int threads : {1, 2}) {
    std::vector<JointMove<3>> moves;
    tbb::task_arena(threads).execute([&] { solveJointPushOut<3>(bodies, points, sweeps, tolerance, moves); });
    ASSERT_EQ(moves.size(), reference.size());
    for (std::size_t b = 0; b < moves.size(); ++b) {
      EXPECT_EQ(moves[b].dx, reference[b].dx) << "body " << b << ", " << threads << " threads";
      EXPECT_EQ(moves[b].dtheta, reference[b].dtheta) << "body " << b << ", " << threads << " threads";
    }
  }
  // The jams did stop at different sweeps on their own: each one's sweeps over its own points
  // differ from what the joint stop left it.
  const std::vector<JointPoint<3>> shortChain(chains[2].begin(), chains[2].end());
  std::vector<JointBody<3>> shortBodies(bodies.begin() + 115, bodies.end());
  std::vector<JointPoint<3>> shifted = shortChain;
  for (auto& p : shifted) {
    p.a -= 115;
    if (p.b >= 0) p.b -= 115;
  }
  const std::vector<JointMove<3>> alone = sweepsOverAllPoints<3>(shortBodies, shifted, sweeps, tolerance);
  bool differs = false;
  for (std::size_t b = 0; b < alone.size(); ++b) differs |= alone[b].dx != reference[115 + b].dx;
  EXPECT_TRUE(differs) << "the test's jams stop at the same sweep: it does not check the shared stop";
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
