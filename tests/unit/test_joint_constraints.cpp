// solvers/articulation: the rows are the time derivative of the joint error (checked by finite
// differences for every joint type), the effective mass is symmetric positive definite, pairwise
// and global projections reach the same velocities and never add kinetic energy, and
// pre-stabilization closes the predicted poses.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "solvers/articulation/joint_closing.h"
#include "solvers/articulation/joint_constraints.h"
#include "solvers/rigid_rotation.h"

using namespace monolith::solvers;

namespace {

ConstraintBody randomBody(std::mt19937& rng, bool dynamic) {
  std::uniform_real_distribution<double> u(-1, 1);
  ConstraintBody b;
  b.x = Eigen::Vector3d(u(rng), u(rng), u(rng));
  b.q = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized());
  b.v = Eigen::Vector3d(u(rng), u(rng), u(rng));
  b.w = Eigen::Vector3d(u(rng), u(rng), u(rng));
  if (dynamic) {
    b.invMass = 1 / (1.5 + u(rng));
    const Eigen::Matrix3d R = b.q.toRotationMatrix();
    const Eigen::Vector3d moments(0.5 + 0.2 * u(rng), 0.8 + 0.2 * u(rng), 1.1 + 0.2 * u(rng));
    b.invInertia = R * moments.cwiseInverse().asDiagonal() * R.transpose();
  }
  return b;
}

// A joint whose frames coincide at the bodies' poses (zero error), of the given type.
JointDefinition closedJoint(JointKind type, const std::vector<ConstraintBody>& bodies, int parent, int child,
                            const Eigen::Vector3d& anchor, const Eigen::Quaterniond& frame) {
  JointDefinition j;
  j.type = type;
  j.parent = parent, j.child = child;
  j.parentAnchor = bodies[parent].q.conjugate() * (anchor - bodies[parent].x);
  j.childAnchor = bodies[child].q.conjugate() * (anchor - bodies[child].x);
  j.parentFrame = bodies[parent].q.conjugate() * frame;
  j.childFrame = bodies[child].q.conjugate() * frame;
  return j;
}

// The child moved off the joint by a small offset and turned by a small rotation, then the error's
// rate under the bodies' velocities by central differences against the rows.
void checkRowsAreErrorRates(JointKind type) {
  std::mt19937 rng(7 + static_cast<int>(type));
  std::vector<ConstraintBody> bodies{randomBody(rng, true), randomBody(rng, true)};
  const Eigen::Quaterniond frame(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  JointDefinition j = closedJoint(type, bodies, 0, 1, Eigen::Vector3d(0.2, -0.1, 0.3), frame);
  // A revolute joint a quarter turn into its free twist; a prismatic one slid along its axis.
  if (type == JointKind::Revolute || type == JointKind::Twist) j.childFrame = j.childFrame * Eigen::Quaterniond(Eigen::AngleAxisd(1.3, Eigen::Vector3d::UnitZ()));
  if (type == JointKind::Prismatic || type == JointKind::Twist) j.childAnchor += Eigen::Vector3d(0.05, 0.02, 0.4);
  const JointRows rows = jointRows(j, bodies);
  const Vector6d rates = rowVelocities(rows, bodies);
  const double h = 1e-6;
  // The error measured along the rows of the moved poses (the rows turn with the parent).
  auto errorAt = [&](double t) {
    auto moved = bodies;
    for (auto& b : moved) {
      b.x += t * b.v;
      b.q = rotationExponential(t * b.w) * b.q;
    }
    const JointError e = jointError(j, moved[0].x, moved[0].q, moved[1].x, moved[1].q);
    return rowsOf(jointRows(j, moved), e.linear, e.angular);
  };
  const Vector6d numeric = (errorAt(h) - errorAt(-h)) / (2 * h);
  for (int i = 0; i < rows.rows(); ++i) EXPECT_NEAR(numeric(i), rates(i), 1e-6) << "type " << static_cast<int>(type) << " row " << i;
  const auto K = effectiveMass(rows, bodies);
  const int k = rows.rows();
  EXPECT_LT((K.topLeftCorner(k, k) - K.topLeftCorner(k, k).transpose()).norm(), 1e-12);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K.topLeftCorner(k, k)).eigenvalues().minCoeff(), 0);
}

double kinetic(const std::vector<ConstraintBody>& bodies) {
  double e = 0;
  for (const auto& b : bodies) {
    if (b.invMass == 0) continue;
    e += 0.5 * b.v.squaredNorm() / b.invMass + 0.5 * b.w.dot(b.invInertia.inverse() * b.w);
  }
  return e;
}

}  // namespace

TEST(JointConstraints, RowsAreTheRatesOfTheJointErrorForEveryType) {
  for (JointKind t : {JointKind::Fixed, JointKind::Revolute, JointKind::Spherical, JointKind::Prismatic,
                      JointKind::Universal, JointKind::Twist})
    checkRowsAreErrorRates(t);
}

TEST(JointConstraints, PairwiseAndGlobalProjectionsAgreeAndRemoveEnergy) {
  // A closed loop of six bodies on spherical joints plus a fixed, a revolute and a universal joint
  // to the world: redundant-free rows, so both reach the one projection.
  std::mt19937 rng(3);
  std::vector<ConstraintBody> bodies{ConstraintBody{}};
  for (int i = 0; i < 6; ++i) bodies.push_back(randomBody(rng, true));
  std::vector<JointRows> rows;
  const Eigen::Quaterniond frame = Eigen::Quaterniond::Identity();
  for (int i = 1; i <= 6; ++i) {
    const int next = i % 6 + 1;
    rows.push_back(jointRows(closedJoint(JointKind::Spherical, bodies, i, next, 0.5 * (bodies[i].x + bodies[next].x), frame), bodies));
  }
  rows.push_back(jointRows(closedJoint(JointKind::Revolute, bodies, 0, 1, bodies[1].x, frame), bodies));
  const std::vector<Vector6d> zero(rows.size(), Vector6d::Zero());
  auto pairwise = bodies, global = bodies;
  const ProjectionReport p = projectPairwise(rows, zero, pairwise, 100000, 1e-14);
  const ProjectionReport g = projectGlobal(rows, zero, global, 10000, 1e-14);
  EXPECT_LT(p.residual, 1e-13);
  EXPECT_LT(g.residual, 1e-13);
  double worst = 0;
  for (std::size_t i = 1; i < bodies.size(); ++i)
    worst = std::max({worst, (pairwise[i].v - global[i].v).cwiseAbs().maxCoeff(), (pairwise[i].w - global[i].w).cwiseAbs().maxCoeff()});
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(kinetic(global), kinetic(bodies));
  // Early termination of unpreconditioned CG never raises the kinetic energy (App. C.1.3).
  for (int iterations = 1; iterations <= 5; ++iterations) {
    auto early = bodies;
    projectGlobal(rows, zero, early, iterations, 0);
    EXPECT_LE(kinetic(early), kinetic(bodies) * (1 + 1e-14)) << iterations << " iterations";
  }
}

TEST(JointConstraints, PreStabilizationClosesThePredictedPoses) {
  std::mt19937 rng(11);
  std::vector<ConstraintBody> bodies{ConstraintBody{}, randomBody(rng, true), randomBody(rng, true)};
  std::vector<JointDefinition> joints{
      closedJoint(JointKind::Revolute, bodies, 0, 1, bodies[1].x + Eigen::Vector3d(0.3, 0, 0), Eigen::Quaterniond::Identity()),
      closedJoint(JointKind::Fixed, bodies, 1, 2, 0.5 * (bodies[1].x + bodies[2].x), Eigen::Quaterniond::Identity())};
  const double dt = 0.02;
  // First-order evolution as the predictor: x + dt v, exp(dt w) q.
  const PosePredictor predict = [&](int i, const ConstraintBody& b, Eigen::Vector3d& x, Eigen::Quaterniond& q) {
    x = i == 0 ? b.x : Eigen::Vector3d(b.x + dt * b.v);
    q = i == 0 ? b.q : Eigen::Quaterniond((rotationExponential(dt * b.w) * b.q).normalized());
  };
  for (bool global : {false, true}) {
    auto state = bodies;
    // Gauss-Seidel over the two joints converges linearly (by about 0.9 a sweep here: the
    // hinge must drag the second body through the fixed joint); Newton on all at once in 5.
    const PreStabilizationReport r = preStabilize(joints, state, predict, dt, global, global ? 10 : 1000, 1e-12);
    EXPECT_GT(r.errorBefore, 1e-3);
    EXPECT_LT(r.errorAfter, 1e-12) << (global ? "global" : "pairwise");
  }
}

// A ring of four bars in the xy plane: with hinges about z at its corners the ring's out-of-plane
// rows repeat (3 of the closing hinge's 5: a planar loop), with ball joints none do, and a tree
// (the same joints without the closing one) never repeats a row.
TEST(JointConstraints, RedundantLoopsAreFoundAtTheJointThatClosesThem) {
  std::vector<ConstraintBody> bodies(5);  // 0: the world (unused), 1..4 the bars
  const Eigen::Vector3d corner[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (int k = 0; k < 4; ++k) {
    bodies[k + 1].x = 0.5 * (corner[k] + corner[(k + 1) % 4]);
    bodies[k + 1].invMass = 1;
    bodies[k + 1].invInertia = Eigen::Matrix3d::Identity();
  }
  auto ring = [&](JointKind type, int joints) {
    std::vector<JointDefinition> out;
    for (int k = 0; k < joints; ++k)
      out.push_back(closedJoint(type, bodies, 1 + (k + 3) % 4, 1 + k, corner[k], Eigen::Quaterniond::Identity()));
    return out;
  };
  const RedundantJoint hinges = firstRedundantJoint(ring(JointKind::Revolute, 4), bodies);
  EXPECT_EQ(hinges.joint, 3);
  EXPECT_EQ(hinges.redundantRows, 3);
  EXPECT_EQ(firstRedundantJoint(ring(JointKind::Spherical, 4), bodies).joint, -1);
  EXPECT_EQ(firstRedundantJoint(ring(JointKind::Revolute, 3), bodies).joint, -1);
  // Fixed joints all round: the closing one repeats all six rows.
  EXPECT_EQ(firstRedundantJoint(ring(JointKind::Fixed, 4), bodies).redundantRows, 6);
}

// A body of mass 2 sliding at 1 m/s while falling at 0.5 m/s onto the ground, one contact point at
// its centre (no lever arm): the normal row stops the fall with the impulse m * 0.5 = 1 N s,
// friction 0.6 can take 0.6 N s of the slide's 2 N s, leaving 0.7 m/s; with friction 1 the
// slide's 2 N s exceeds the cone's 1 N s as well, leaving 0.5 m/s.
TEST(JointClosing, ContactRowsStopTheApproachAndHoldSlipWithinTheFrictionCone) {
  for (const double mu : {0.6, 1.0}) {
    std::vector<ConstraintBody> bodies(2);
    bodies[1].invMass = 0.5;
    bodies[1].invInertia = Eigen::Matrix3d::Identity();
    bodies[1].x = Eigen::Vector3d(0, 1, 0);
    bodies[1].v = Eigen::Vector3d(1, -0.5, 0);
    ContactRow c;
    c.a = 1, c.b = 0, c.point = bodies[1].x, c.normal = Eigen::Vector3d::UnitY(), c.friction = mu;
    projectWithContacts({}, {c}, bodies, 50, 1e-12);
    EXPECT_NEAR(bodies[1].v.y(), 0.0, 1e-12);
    EXPECT_NEAR(bodies[1].v.x(), 1.0 - mu * 0.5, 1e-12) << "friction " << mu;
    EXPECT_NEAR(bodies[1].w.norm(), 0.0, 1e-12);
  }
}

// A ball (m = 2, R = 0.07, I = 2/5 m R^2) rolling without slipping at u along x on the ground,
// with gravity's kick of one step in its velocity: Coulomb friction alone keeps the roll; rolling
// resistance r slows it by the torque r N's share, Δv = 5 r g dt / (7 R) (the rolling ball's
// deceleration 5 r g / (7 R)), and stops a slow roll; the kinetic energy never rises.
TEST(JointClosing, RollingResistanceSlowsARollingBallAsItsTorquePredicts) {
  const double m = 2, R = 0.07, g = 9.81, dt = 1.0 / 30, I = 0.4 * m * R * R;
  auto roll = [&](double u, double rolling) {
    std::vector<ConstraintBody> bodies(2);
    ConstraintBody& ball = bodies[1];
    ball.invMass = 1 / m;
    ball.invInertia = Eigen::Matrix3d::Identity() / I;
    ball.x = Eigen::Vector3d(0, R, 0);
    ball.v = Eigen::Vector3d(u, -g * dt, 0);
    ball.w = Eigen::Vector3d(0, 0, -u / R);  // no slip at the contact point
    ContactRow c;
    c.a = 1, c.b = 0, c.point = Eigen::Vector3d::Zero(), c.normal = Eigen::Vector3d::UnitY(), c.friction = 0.6;
    c.rolling = rolling;
    const double before = 0.5 * m * ball.v.squaredNorm() + 0.5 * I * ball.w.squaredNorm();
    projectWithContacts({}, {c}, bodies, 200, 1e-14);
    const double after = 0.5 * m * ball.v.squaredNorm() + 0.5 * I * ball.w.squaredNorm();
    EXPECT_LE(after, before);
    EXPECT_NEAR(ball.v.y(), 0.0, 1e-12);
    EXPECT_NEAR(ball.v.x() + R * ball.w.z(), 0.0, 1e-12) << "rolls without slipping";
    return ball.v.x();
  };
  EXPECT_NEAR(roll(0.1, 0.0), 0.1, 1e-12);
  const double r = 1e-3;
  EXPECT_NEAR(roll(0.1, r), 0.1 - 5 * r * g * dt / (7 * R), 1e-12);
  EXPECT_NEAR(roll(0.002, r), 0.0, 1e-12) << "a roll slower than one step's resistance stops";
}

// Two unit bodies on a ball joint 0.1 m apart, the child on a floor (a contact row that lets it
// gain separation but not lose it), the parent below it (over a hole): closing the joint moves
// the parent up to the child and not the child into the floor, where closeJoints alone moves
// each half way.
TEST(JointClosing, JointsCloseWithoutPushingBodiesIntoTheirContacts) {
  std::vector<ConstraintBody> bodies(3);
  for (int i : {1, 2}) {
    bodies[i].invMass = 1;
    bodies[i].invInertia = Eigen::Matrix3d::Identity();
  }
  bodies[1].x = Eigen::Vector3d(0, -0.1, 0);  // parent, its anchor at its centre
  bodies[2].x = Eigen::Vector3d(0, 0, 0);    // child on the floor, anchor at its centre
  JointDefinition j;
  j.type = JointKind::Spherical;
  j.parent = 1, j.child = 2;
  ContactRow floor;
  floor.a = 2, floor.b = 0, floor.point = bodies[2].x, floor.normal = Eigen::Vector3d::UnitY();
  std::vector<ConstraintBody> free = bodies;
  closeJoints({j}, free, false, 20, 1e-12);
  EXPECT_NEAR(free[2].x.y(), -0.05, 1e-9);
  const PreStabilizationReport r = closeJointsAgainstContacts({j}, bodies, {floor}, 50, false, 20, 1e-12);
  EXPECT_NEAR(r.errorBefore, 0.1, 1e-12);
  EXPECT_LT(r.errorAfter, 1e-12);
  EXPECT_NEAR(bodies[2].x.y(), 0.0, 1e-9);
  EXPECT_NEAR(bodies[1].x.y(), 0.0, 1e-9);
}
