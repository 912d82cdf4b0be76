#include "solvers/articulation/joint_closing.h"

#include <algorithm>
#include <cmath>

#include "solvers/rigid_rotation.h"

namespace monolith::solvers {

namespace {

// The contact rows linearised at the current poses: per point its arms, its directions (the
// normal, then two tangents), each row's inverse effective mass and the impulses so far.
struct LinearContact {
  Eigen::Vector3d armA, armB;
  Eigen::Matrix3d dirs;
  double inverseK[3] = {0, 0, 0};
  double impulse[3] = {0, 0, 0};
  // Rolling resistance: angular rows about the two tangents (dirs' columns 1 and 2).
  double inverseKRolling[2] = {0, 0};
  double rollingImpulse[2] = {0, 0};
};

std::vector<LinearContact> linearise(const std::vector<ContactRow>& contacts, const std::vector<ConstraintBody>& bodies) {
  std::vector<LinearContact> linear(contacts.size());
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const ContactRow& c = contacts[k];
    const ConstraintBody& A = bodies[c.a];
    const ConstraintBody& B = bodies[c.b];
    LinearContact& l = linear[k];
    l.armA = c.point - A.x;
    l.armB = c.point - B.x;
    const Eigen::Vector3d t1 = c.normal.unitOrthogonal();
    l.dirs << c.normal, t1, c.normal.cross(t1);
    for (int row = 0; row < 3; ++row) {
      const Eigen::Vector3d n = l.dirs.col(row);
      const Eigen::Vector3d turnA = l.armA.cross(n), turnB = l.armB.cross(n);
      const double K = A.invMass + B.invMass + turnA.dot(A.invInertia * turnA) + turnB.dot(B.invInertia * turnB);
      l.inverseK[row] = K > 0 ? 1 / K : 0;
    }
    for (int row = 0; row < 2 && c.rolling > 0; ++row) {
      const Eigen::Vector3d t = l.dirs.col(row + 1);
      const double K = t.dot(A.invInertia * t) + t.dot(B.invInertia * t);
      l.inverseKRolling[row] = K > 0 ? 1 / K : 0;
    }
  }
  return linear;
}

// The motion of the point on a relative to b along one of its directions (the partners' own
// motion, `offset`, included).
double relativeMove(const ContactRow& c, const LinearContact& l, const std::vector<ConstraintBody>& moves, int row) {
  const ConstraintBody& A = moves[c.a];
  const ConstraintBody& B = moves[c.b];
  return l.dirs.col(row).dot(A.v + A.w.cross(l.armA) - B.v - B.w.cross(l.armB) + c.offset);
}

void applyContactImpulse(const ContactRow& c, const LinearContact& l, int row, double delta,
                         std::vector<ConstraintBody>& moves) {
  ConstraintBody& A = moves[c.a];
  ConstraintBody& B = moves[c.b];
  const Eigen::Vector3d n = l.dirs.col(row);
  const Eigen::Vector3d torqueA = delta * l.armA.cross(n), torqueB = -delta * l.armB.cross(n);
  A.v += A.invMass * delta * n;
  A.w += A.invInertia * torqueA;
  B.v -= B.invMass * delta * n;
  B.w += B.invInertia * torqueB;
  if (A.invMass > 0) A.angularImpulse += torqueA;
  if (B.invMass > 0) B.angularImpulse += torqueB;
}

// An angular impulse `delta` about the tangent `t` on a, its opposite on b.
void applyRollingImpulse(const ContactRow& c, const Eigen::Vector3d& t, double delta, std::vector<ConstraintBody>& moves) {
  ConstraintBody& A = moves[c.a];
  ConstraintBody& B = moves[c.b];
  A.w += A.invInertia * (delta * t);
  B.w -= B.invInertia * (delta * t);
  if (A.invMass > 0) A.angularImpulse += delta * t;
  if (B.invMass > 0) B.angularImpulse -= delta * t;
}

// One projected Gauss-Seidel sweep over the contact rows; returns the largest normal row left
// short of its gain and, at points with rolling resistance, the largest velocity change of
// their friction and rolling rows (rolling resistance turns slip into roll and back, so those
// rows must settle too; without it one friction update per point stops the slip).
double sweepContacts(const std::vector<ContactRow>& contacts, std::vector<LinearContact>& linear,
                     std::vector<ConstraintBody>& moves) {
  double worst = 0;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const ContactRow& c = contacts[k];
    LinearContact& l = linear[k];
    if (l.inverseK[0] == 0) continue;
    const double missing = c.gain - relativeMove(c, l, moves, 0);
    const double next = std::max(0.0, l.impulse[0] + missing * l.inverseK[0]);
    worst = std::max(worst, missing);
    applyContactImpulse(c, l, 0, next - l.impulse[0], moves);
    l.impulse[0] = next;
    // Friction: no slip, while the tangential impulse stays in the cone of the normal one.
    const double bound = c.friction * l.impulse[0];
    Eigen::Vector2d t(l.impulse[1] - relativeMove(c, l, moves, 1) * l.inverseK[1],
                      l.impulse[2] - relativeMove(c, l, moves, 2) * l.inverseK[2]);
    if (t.norm() > bound) t *= bound / t.norm();
    for (int row = 1; row < 3; ++row) {
      const double delta = t(row - 1) - l.impulse[row];
      if (c.rolling > 0 && l.inverseK[row] > 0) worst = std::max(worst, std::abs(delta) / l.inverseK[row]);
      applyContactImpulse(c, l, row, delta, moves);
      l.impulse[row] = t(row - 1);
    }
    if (c.rolling <= 0) continue;
    // Rolling resistance: no relative turn about the tangents, while the angular impulse stays in
    // the disc of rolling x the normal impulse (dissipative like friction: it only ever opposes
    // the relative turn it finds, up to stopping it).
    const Eigen::Vector3d turn = moves[c.a].w - moves[c.b].w;
    Eigen::Vector2d r(l.rollingImpulse[0] - l.dirs.col(1).dot(turn) * l.inverseKRolling[0],
                      l.rollingImpulse[1] - l.dirs.col(2).dot(turn) * l.inverseKRolling[1]);
    const double rollingBound = c.rolling * l.impulse[0];
    if (r.norm() > rollingBound) r *= rollingBound / r.norm();
    for (int row = 0; row < 2; ++row) {
      const double delta = r(row) - l.rollingImpulse[row];
      if (l.inverseKRolling[row] > 0) worst = std::max(worst, std::abs(delta) / l.inverseKRolling[row]);
      applyRollingImpulse(c, l.dirs.col(row + 1), delta, moves);
      l.rollingImpulse[row] = r(row);
    }
  }
  return worst;
}

}  // namespace

PreStabilizationReport closeJointsAgainstContacts(const std::vector<JointDefinition>& joints,
                                                  std::vector<ConstraintBody>& bodies,
                                                  const std::vector<ContactRow>& contacts, int sweeps, bool global,
                                                  int maxIterations, double tolerance) {
  // The moves are carried as velocities over a step of 1 (closeJoints' convention).
  std::vector<ConstraintBody> moves = bodies;
  for (auto& b : moves) b.v.setZero(), b.w.setZero(), b.angularImpulse.setZero();
  const PosePredictor displaced = [](int, const ConstraintBody& b, Eigen::Vector3d& x, Eigen::Quaterniond& q) {
    x = b.x + b.v;
    q = b.invMass > 0 ? Eigen::Quaterniond((rotationExponential(b.w) * b.q).normalized()) : b.q;
  };
  std::vector<LinearContact> linear = linearise(contacts, bodies);
  PreStabilizationReport report;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    const double worst = sweepContacts(contacts, linear, moves);
    // The joints last in each sweep: one Newton step per joint (they are nonlinear in the turns).
    const PreStabilizationReport r = preStabilize(joints, moves, displaced, 1.0, false, 1, tolerance);
    if (sweep == 0) report.errorBefore = r.errorBefore;
    report.iterations += r.iterations;
    if (r.errorBefore <= tolerance && worst <= tolerance) break;
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].invMass == 0) continue;
    displaced(static_cast<int>(i), moves[i], bodies[i].x, bodies[i].q);
  }
  // What the sweeps leave open (the contacts may hold a joint apart): closed without them.
  const PreStabilizationReport last = closeJoints(joints, bodies, global, maxIterations, tolerance);
  if (sweeps == 0) report.errorBefore = last.errorBefore;
  report.iterations += last.iterations;
  report.errorAfter = last.errorAfter;
  return report;
}

ProjectionReport projectWithContacts(const std::vector<JointRows>& joints, const std::vector<ContactRow>& contacts,
                                     std::vector<ConstraintBody>& bodies, int sweeps, double tolerance) {
  std::vector<LinearContact> linear = linearise(contacts, bodies);
  const std::vector<Vector6d> zero(joints.size(), Vector6d::Zero());
  ProjectionReport report;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    const double worst = sweepContacts(contacts, linear, bodies);
    const ProjectionReport r = projectPairwise(joints, zero, bodies, 1, tolerance);
    report.iterations = sweep + 1;
    report.residual = r.residual;
    if (r.residual <= tolerance && worst <= tolerance) break;
  }
  return report;
}

}  // namespace monolith::solvers
