#include "solvers/articulation/joint_constraints.h"

#include <Eigen/QR>
#include <functional>

#include "solvers/rigid_rotation.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace monolith::solvers {

namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Quaterniond positiveScalar(Eigen::Quaterniond q) {
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return q;
}

// Velocity changes of the parent and child from a row impulse.
struct Response {
  Eigen::Vector3d vParent, wParent, vChild, wChild, torqueParent, torqueChild;
};

Response responseTo(const JointRows& rows, const Vector6d& lambda, const std::vector<ConstraintBody>& bodies) {
  Eigen::Vector3d J = Eigen::Vector3d::Zero(), T = Eigen::Vector3d::Zero();
  for (int i = 0; i < rows.linear; ++i) J += lambda(i) * rows.linearDirs.col(i);
  for (int i = 0; i < rows.angular; ++i) T += lambda(rows.linear + i) * rows.angularDirs.col(i);
  const ConstraintBody& P = bodies[rows.parent];
  const ConstraintBody& C = bodies[rows.child];
  Response r;
  r.torqueChild = rows.armChild.cross(J) + T;
  r.torqueParent = -(rows.armParent.cross(J) + T);
  r.vChild = C.invMass * J;
  r.wChild = C.invInertia * r.torqueChild;
  r.vParent = -P.invMass * J;
  r.wParent = P.invInertia * r.torqueParent;
  return r;
}

Vector6d rowsOfMotion(const JointRows& rows, const Eigen::Vector3d& vP, const Eigen::Vector3d& wP,
                      const Eigen::Vector3d& vC, const Eigen::Vector3d& wC) {
  const Eigen::Vector3d lin = vC + wC.cross(rows.armChild) - vP - wP.cross(rows.armParent);
  return rowsOf(rows, lin, wC - wP);
}

double maxAbs(const Vector6d& r, int n) { return largestEntry(r, n); }

using Ldlt6 = Eigen::LDLT<Eigen::MatrixXd>;

Ldlt6 factor(const JointRows& rows, const std::vector<ConstraintBody>& bodies) {
  const int k = rows.rows();
  return Ldlt6(effectiveMass(rows, bodies).topLeftCorner(k, k));
}

Vector6d solveRows(const Ldlt6& K, const Vector6d& rhs, int k) {
  Vector6d out = Vector6d::Zero();
  if (k > 0) out.head(k) = K.solve(rhs.head(k).eval());
  return out;
}

// Whether a limit row is on: the coordinate past a limit, or at it (within limitSlack) and moving
// further out.
bool pastLimit(double value, double rate, double lower, double upper) {
  const bool pastUpper = value > upper || (value >= upper - limitSlack && rate > 0);
  const bool pastLower = value < lower || (value <= lower + limitSlack && rate < 0);
  return pastUpper || pastLower;
}

// The hinge's angle limit (revolute, twist) about the parent frame's axis.
bool angleLimitActive(const JointDefinition& joint, const ConstraintBody& P, const ConstraintBody& C,
                      const Eigen::Vector3d& axis) {
  if (!joint.limited) return false;
  return pastLimit(revoluteAngle(joint, P.q, C.q), axis.dot(C.w - P.w), joint.lower, joint.upper);
}

// The slide limit (prismatic, twist): the child's anchor along the axis from the parent's, and its
// rate, the relative velocity at the child's anchor along the axis (the row's own velocity).
bool slideLimitActive(const JointDefinition& joint, const JointRows& rows, const ConstraintBody& P,
                      const ConstraintBody& C, const Eigen::Vector3d& axis) {
  if (!joint.slideLimited) return false;
  const double slide = axis.dot((C.x + C.q * joint.childAnchor) - (P.x + P.q * joint.parentAnchor));
  const double rate = axis.dot(C.v + C.w.cross(rows.armChild) - P.v - P.w.cross(rows.armParent));
  return pastLimit(slide, rate, joint.slideLower, joint.slideUpper);
}

// A planar joint's frames turn about z only, so each of its row directions lies in the plane or
// along z (to rounding): keep the linear rows in the plane and the angular rows about z.
void keepInPlane(JointRows& rows) {
  int kept = 0;
  for (int i = 0; i < rows.linear; ++i)
    if (std::abs(rows.linearDirs(2, i)) < 0.5) rows.linearDirs.col(kept++) = rows.linearDirs.col(i);
  rows.linear = kept;
  kept = 0;
  for (int i = 0; i < rows.angular; ++i)
    if (std::abs(rows.angularDirs(2, i)) > 0.5) rows.angularDirs.col(kept++) = rows.angularDirs.col(i);
  rows.angular = kept;
}

}  // namespace

double largestEntry(const Vector6d& v, int n) {
  double m = 0;
  for (int i = 0; i < n; ++i) m = std::max(m, std::abs(v(i)));
  return m;
}

Vector6d rowsOf(const JointRows& rows, const Eigen::Vector3d& linear, const Eigen::Vector3d& angular) {
  Vector6d out = Vector6d::Zero();
  for (int i = 0; i < rows.linear; ++i) out(i) = rows.linearDirs.col(i).dot(linear);
  for (int i = 0; i < rows.angular; ++i) out(rows.linear + i) = rows.angularDirs.col(i).dot(angular);
  return out;
}

JointRows jointRows(const JointDefinition& joint, const std::vector<ConstraintBody>& bodies) {
  const ConstraintBody& P = bodies[joint.parent];
  const ConstraintBody& C = bodies[joint.child];
  JointRows rows;
  rows.parent = joint.parent;
  rows.child = joint.child;
  const Eigen::Vector3d anchor = C.x + C.q * joint.childAnchor;
  rows.armParent = anchor - P.x;
  rows.armChild = anchor - C.x;
  const Eigen::Matrix3d Fp = (P.q * joint.parentFrame).toRotationMatrix();
  const Eigen::Matrix3d Fc = (C.q * joint.childFrame).toRotationMatrix();
  switch (joint.type) {
    case JointKind::Fixed:
      rows.linear = 3, rows.linearDirs = Fp;
      rows.angular = 3, rows.angularDirs = Fp;
      break;
    case JointKind::Revolute: {
      rows.linear = 3, rows.linearDirs = Fp;
      rows.angular = 2, rows.angularDirs.leftCols<2>() = Fp.leftCols<2>();
      if (angleLimitActive(joint, P, C, Fp.col(2))) rows.angular = 3, rows.angularDirs.col(2) = Fp.col(2);
      break;
    }
    case JointKind::Spherical:
      rows.linear = 3, rows.linearDirs = Fp;
      break;
    case JointKind::Prismatic:
      rows.linear = 2, rows.linearDirs.leftCols<2>() = Fp.leftCols<2>();
      rows.angular = 3, rows.angularDirs = Fp;
      if (slideLimitActive(joint, rows, P, C, Fp.col(2))) rows.linear = 3, rows.linearDirs.col(2) = Fp.col(2);
      break;
    case JointKind::Twist:
      rows.linear = 2, rows.linearDirs.leftCols<2>() = Fp.leftCols<2>();
      rows.angular = 2, rows.angularDirs.leftCols<2>() = Fp.leftCols<2>();
      if (slideLimitActive(joint, rows, P, C, Fp.col(2))) rows.linear = 3, rows.linearDirs.col(2) = Fp.col(2);
      if (angleLimitActive(joint, P, C, Fp.col(2))) rows.angular = 3, rows.angularDirs.col(2) = Fp.col(2);
      break;
    case JointKind::Universal: {
      rows.linear = 3, rows.linearDirs = Fp;
      const Eigen::Vector3d n = Fp.col(0).cross(Fc.col(1));
      // The two axes parallel: the joint is at its singular pose; constrain the parent's normal.
      rows.angular = 1;
      rows.angularDirs.col(0) = n.norm() > 1e-6 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d(Fp.col(2));
      break;
    }
  }
  if (joint.planar) keepInPlane(rows);
  return rows;
}

JointError jointError(const JointDefinition& joint, const Eigen::Vector3d& xParent, const Eigen::Quaterniond& qParent,
                      const Eigen::Vector3d& xChild, const Eigen::Quaterniond& qChild) {
  JointError e;
  const Eigen::Quaterniond qP = qParent * joint.parentFrame, qC = qChild * joint.childFrame;
  const Eigen::Vector3d axis = qP * Eigen::Vector3d::UnitZ();
  e.linear = (xChild + qChild * joint.childAnchor) - (xParent + qParent * joint.parentAnchor);
  if (joint.type == JointKind::Prismatic || joint.type == JointKind::Twist) {
    const double slide = axis.dot(e.linear);
    e.linear -= axis * slide;
    // Past a slide limit, the overshoot along the axis is an error too.
    if (joint.slideLimited && slide > joint.slideUpper) e.linear += (slide - joint.slideUpper) * axis;
    if (joint.slideLimited && slide < joint.slideLower) e.linear += (slide - joint.slideLower) * axis;
  }
  switch (joint.type) {
    case JointKind::Fixed:
    case JointKind::Prismatic:
      e.angular = 2 * positiveScalar(qC * qP.conjugate()).vec();
      break;
    case JointKind::Revolute:
    case JointKind::Twist: {
      // Remove the free twist about the hinge first, so that what remains is the error alone
      // (the vector part of q_c q_p^-1 would else mix the twist into the perpendicular rows).
      const double twist = revoluteAngle(joint, qParent, qChild);
      const Eigen::Quaterniond untwisted = qC * Eigen::Quaterniond(Eigen::AngleAxisd(-twist, Eigen::Vector3d::UnitZ()));
      e.angular = 2 * positiveScalar(untwisted * qP.conjugate()).vec();
      e.angular -= axis * axis.dot(e.angular);
      if (joint.limited && twist > joint.upper) e.angular += (twist - joint.upper) * axis;
      if (joint.limited && twist < joint.lower) e.angular += (twist - joint.lower) * axis;
      break;
    }
    case JointKind::Universal: {
      const Eigen::Vector3d a = qP * Eigen::Vector3d::UnitX(), b = qC * Eigen::Vector3d::UnitY();
      const Eigen::Vector3d n = a.cross(b);
      const double s = n.norm();
      if (s > 1e-6) e.angular = std::atan2(-a.dot(b), s) * n / s;
      break;
    }
    case JointKind::Spherical:
      break;
  }
  return e;
}

double revoluteAngle(const JointDefinition& joint, const Eigen::Quaterniond& qParent, const Eigen::Quaterniond& qChild) {
  const Eigen::Quaterniond rel = (qParent * joint.parentFrame).conjugate() * (qChild * joint.childFrame);
  double a = 2 * std::atan2(rel.z(), rel.w());
  if (a > kPi) a -= 2 * kPi;
  if (a <= -kPi) a += 2 * kPi;
  return a;
}

Eigen::Vector3d jointAxis(const JointDefinition& joint, const Eigen::Quaterniond& qParent) {
  return (qParent * joint.parentFrame) * Eigen::Vector3d::UnitZ();
}

Vector6d rowVelocities(const JointRows& rows, const std::vector<ConstraintBody>& bodies) {
  const ConstraintBody& P = bodies[rows.parent];
  const ConstraintBody& C = bodies[rows.child];
  return rowsOfMotion(rows, P.v, P.w, C.v, C.w);
}

void applyRowImpulse(const JointRows& rows, const Vector6d& lambda, std::vector<ConstraintBody>& bodies) {
  const Response r = responseTo(rows, lambda, bodies);
  ConstraintBody& P = bodies[rows.parent];
  ConstraintBody& C = bodies[rows.child];
  C.v += r.vChild;
  C.w += r.wChild;
  P.v += r.vParent;
  P.w += r.wParent;
  if (C.invMass > 0) C.angularImpulse += r.torqueChild;
  if (P.invMass > 0) P.angularImpulse += r.torqueParent;
}

Eigen::Matrix<double, 6, 6> effectiveMass(const JointRows& rows, const std::vector<ConstraintBody>& bodies) {
  Eigen::Matrix<double, 6, 6> K = Eigen::Matrix<double, 6, 6>::Zero();
  for (int j = 0; j < rows.rows(); ++j) {
    const Response r = responseTo(rows, Vector6d::Unit(j), bodies);
    K.col(j) = rowsOfMotion(rows, r.vParent, r.wParent, r.vChild, r.wChild);
  }
  return K;
}

ProjectionReport projectPairwise(const std::vector<JointRows>& joints, const std::vector<Vector6d>& targets,
                                 std::vector<ConstraintBody>& bodies, int maxSweeps, double tolerance) {
  std::vector<Ldlt6> K;
  K.reserve(joints.size());
  for (const auto& j : joints) K.push_back(factor(j, bodies));
  ProjectionReport report;
  for (int sweep = 0; sweep < maxSweeps; ++sweep) {
    double worst = 0;
    for (std::size_t j = 0; j < joints.size(); ++j) {
      const int k = joints[j].rows();
      const Vector6d r = targets[j] - rowVelocities(joints[j], bodies);
      worst = std::max(worst, maxAbs(r, k));
      applyRowImpulse(joints[j], solveRows(K[j], r, k), bodies);
    }
    report.iterations = sweep + 1;
    if (worst <= tolerance) break;
  }
  for (std::size_t j = 0; j < joints.size(); ++j)
    report.residual = std::max(report.residual, maxAbs(targets[j] - rowVelocities(joints[j], bodies), joints[j].rows()));
  return report;
}

ProjectionReport projectGlobal(const std::vector<JointRows>& joints, const std::vector<Vector6d>& targets,
                               std::vector<ConstraintBody>& bodies, int maxIterations, double tolerance) {
  const std::size_t J = joints.size();
  std::vector<int> offset(J + 1, 0);
  for (std::size_t j = 0; j < J; ++j) offset[j + 1] = offset[j] + joints[j].rows();
  const int n = offset[J];
  auto segment = [&](const Eigen::VectorXd& x, std::size_t j) {
    Vector6d s = Vector6d::Zero();
    s.head(joints[j].rows()) = x.segment(offset[j], joints[j].rows());
    return s;
  };
  // G^T M^-1 G x: the bodies' velocity changes from all row impulses, then every joint's rows.
  std::vector<Eigen::Vector3d> dv(bodies.size()), dw(bodies.size());
  auto apply = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
    std::fill(dv.begin(), dv.end(), Eigen::Vector3d::Zero());
    std::fill(dw.begin(), dw.end(), Eigen::Vector3d::Zero());
    for (std::size_t j = 0; j < J; ++j) {
      const Response r = responseTo(joints[j], segment(x, j), bodies);
      dv[joints[j].parent] += r.vParent, dw[joints[j].parent] += r.wParent;
      dv[joints[j].child] += r.vChild, dw[joints[j].child] += r.wChild;
    }
    for (std::size_t j = 0; j < J; ++j) {
      const JointRows& rows = joints[j];
      out.segment(offset[j], rows.rows()) =
          rowsOfMotion(rows, dv[rows.parent], dw[rows.parent], dv[rows.child], dw[rows.child]).head(rows.rows());
    }
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), r(n), p(n), Ap(n);
  for (std::size_t j = 0; j < J; ++j)
    r.segment(offset[j], joints[j].rows()) = (targets[j] - rowVelocities(joints[j], bodies)).head(joints[j].rows());
  p = r;
  double rr = r.squaredNorm();
  ProjectionReport report;
  for (int it = 0; it < maxIterations && n > 0; ++it) {
    if (r.cwiseAbs().maxCoeff() <= tolerance) break;
    apply(p, Ap);
    const double pAp = p.dot(Ap);
    if (!(pAp > 0)) break;  // the rest lies in G's nullspace (redundant rows of a loop)
    const double alpha = rr / pAp;
    x += alpha * p;
    r -= alpha * Ap;
    const double rrNew = r.squaredNorm();
    p = r + (rrNew / rr) * p;
    rr = rrNew;
    report.iterations = it + 1;
  }
  for (std::size_t j = 0; j < J; ++j) applyRowImpulse(joints[j], segment(x, j), bodies);
  for (std::size_t j = 0; j < J; ++j)
    report.residual = std::max(report.residual, maxAbs(targets[j] - rowVelocities(joints[j], bodies), joints[j].rows()));
  return report;
}

PreStabilizationReport preStabilize(const std::vector<JointDefinition>& joints, std::vector<ConstraintBody>& bodies,
                                    const PosePredictor& predict, double dt, bool global, int maxIterations,
                                    double tolerance) {
  PreStabilizationReport report;
  const std::size_t J = joints.size();
  // The bodies at the poses Step IV would give them (velocities and inertias as now): the
  // Newton Jacobian takes its arms and directions there, since an impulse now moves the
  // predicted anchor by dt (dv + dw x r) with the arm r of the predicted pose.
  std::vector<ConstraintBody> ahead = bodies;
  auto predictBody = [&](int i) {
    ahead[i] = bodies[i];
    predict(i, bodies[i], ahead[i].x, ahead[i].q);
  };
  auto errorRows = [&](std::size_t j, const JointRows& rows) {
    const JointDefinition& d = joints[j];
    const JointError e = jointError(d, ahead[d.parent].x, ahead[d.parent].q, ahead[d.child].x, ahead[d.child].q);
    return rowsOf(rows, e.linear, e.angular);
  };
  auto predictAll = [&] {
    for (std::size_t i = 0; i < bodies.size(); ++i) predictBody(static_cast<int>(i));
  };
  auto worstError = [&] {
    predictAll();
    double worst = 0;
    for (std::size_t j = 0; j < J; ++j) {
      const JointRows rows = jointRows(joints[j], ahead);
      worst = std::max(worst, maxAbs(errorRows(j, rows), rows.rows()));
    }
    return worst;
  };

  report.errorBefore = worstError();
  const std::vector<ConstraintBody> start = global ? bodies : std::vector<ConstraintBody>{};
  if (report.errorBefore <= tolerance) {
    report.errorAfter = report.errorBefore;
    return report;
  }
  if (!global) {
    for (int it = 0; it < maxIterations; ++it) {
      double worst = 0;
      for (std::size_t j = 0; j < J; ++j) {
        predictBody(joints[j].parent);
        predictBody(joints[j].child);
        const JointRows rows = jointRows(joints[j], ahead);
        const int k = rows.rows();
        const Vector6d e = errorRows(j, rows);
        worst = std::max(worst, maxAbs(e, k));
        applyRowImpulse(rows, solveRows(factor(rows, bodies), -e / dt, k), bodies);
      }
      report.iterations = it + 1;
      if (worst <= tolerance) break;
    }
  } else {
    std::vector<JointRows> rows(J);
    std::vector<Vector6d> targets(J);
    for (int it = 0; it < maxIterations; ++it) {
      predictAll();
      double worst = 0;
      int totalRows = 0;
      for (std::size_t j = 0; j < J; ++j) {
        rows[j] = jointRows(joints[j], ahead);
        totalRows += rows[j].rows();
        const Vector6d e = errorRows(j, rows[j]);
        worst = std::max(worst, maxAbs(e, rows[j].rows()));
        targets[j] = rowVelocities(rows[j], bodies) - e / dt;
      }
      if (worst <= tolerance) break;
      projectGlobal(rows, targets, bodies, std::max(100, 4 * totalRows), 1e-3 * tolerance / dt);
      report.iterations = it + 1;
    }
  }
  report.errorAfter = worstError();
  // The global Newton has no line search: from the large errors of an impact it can leave the
  // joints further open than it found them (ragdoll_pile: 1.8 left in its first impact step).
  // Then pairwise Newton, joint by joint, goes on (from the velocities it was given if the
  // global one made things worse).
  if (global && report.errorAfter > 1e3 * tolerance) {
    if (report.errorAfter > report.errorBefore) bodies = start;
    const PreStabilizationReport pairwise = preStabilize(joints, bodies, predict, dt, false, maxIterations, tolerance);
    report.iterations += pairwise.iterations;
    report.errorAfter = pairwise.errorAfter;
  }
  return report;
}

PreStabilizationReport closeJoints(const std::vector<JointDefinition>& joints, std::vector<ConstraintBody>& bodies,
                                   bool global, int maxIterations, double tolerance) {
  std::vector<ConstraintBody> moves = bodies;
  for (auto& b : moves) b.v.setZero(), b.w.setZero(), b.angularImpulse.setZero();
  const PosePredictor displaced = [](int, const ConstraintBody& b, Eigen::Vector3d& x, Eigen::Quaterniond& q) {
    x = b.x + b.v;
    q = b.invMass > 0 ? Eigen::Quaterniond((rotationExponential(b.w) * b.q).normalized()) : b.q;
  };
  const PreStabilizationReport r = preStabilize(joints, moves, displaced, 1.0, global, maxIterations, tolerance);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].invMass == 0) continue;
    displaced(static_cast<int>(i), moves[i], bodies[i].x, bodies[i].q);
  }
  return r;
}

RedundantJoint firstRedundantJoint(const std::vector<JointDefinition>& joints, const std::vector<ConstraintBody>& bodies) {
  // Union-find over bodies; every immovable body is node 0.
  const int n = static_cast<int>(bodies.size());
  auto nodeOf = [&](int b) { return bodies[b].invMass > 0 ? b + 1 : 0; };
  std::vector<int> up(n + 1);
  for (int i = 0; i <= n; ++i) up[i] = i;
  std::function<int(int)> find = [&](int i) { return up[i] == i ? i : up[i] = find(up[i]); };
  for (std::size_t k = 0; k < joints.size(); ++k) {
    JointDefinition joint = joints[k];
    joint.limited = joint.slideLimited = false;
    const int a = find(nodeOf(joint.parent)), b = find(nodeOf(joint.child));
    if (a != b) {
      up[std::max(a, b)] = std::min(a, b);
      continue;
    }
    // A loop closes: the rows of the component's joints so far, then this joint's.
    std::vector<int> column(n, -1);
    int columns = 0;
    std::vector<std::size_t> members;
    for (std::size_t i = 0; i <= k; ++i) {
      if (find(nodeOf(joints[i].parent)) != a && find(nodeOf(joints[i].child)) != a) continue;
      members.push_back(i);
      for (int body : {joints[i].parent, joints[i].child})
        if (bodies[body].invMass > 0 && column[body] < 0) column[body] = 6 * columns++;
    }
    auto rowsOfJoint = [&](std::size_t i) {
      JointDefinition d = joints[i];
      d.limited = d.slideLimited = false;
      const JointRows r = jointRows(d, bodies);
      Eigen::MatrixXd out = Eigen::MatrixXd::Zero(r.rows(), 6 * columns);
      for (int q = 0; q < r.rows(); ++q) {
        const bool linear = q < r.linear;
        const Eigen::Vector3d dir = linear ? r.linearDirs.col(q) : r.angularDirs.col(q - r.linear);
        auto put = [&](int body, const Eigen::Vector3d& arm, double sign) {
          if (column[body] < 0) return;
          if (linear) {
            out.block<1, 3>(q, column[body]) = sign * dir.transpose();
            out.block<1, 3>(q, column[body] + 3) = sign * arm.cross(dir).transpose();
          } else {
            out.block<1, 3>(q, column[body] + 3) = sign * dir.transpose();
          }
        };
        put(r.child, r.armChild, 1.0);
        put(r.parent, r.armParent, -1.0);
      }
      return out;
    };
    std::vector<Eigen::MatrixXd> blocks;
    int rowsBefore = 0;
    for (std::size_t i : members) {
      blocks.push_back(rowsOfJoint(i));
      if (i != k) rowsBefore += static_cast<int>(blocks.back().rows());
    }
    auto rankOf = [&](bool withLast) {
      const int m = rowsBefore + (withLast ? static_cast<int>(blocks.back().rows()) : 0);
      Eigen::MatrixXd A(m, 6 * columns);
      int at = 0;
      for (std::size_t q = 0; q < blocks.size(); ++q) {
        if (members[q] == k && !withLast) continue;
        A.middleRows(at, blocks[q].rows()) = blocks[q];
        at += static_cast<int>(blocks[q].rows());
      }
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A.transpose());
      qr.setThreshold(1e-9);
      return static_cast<int>(qr.rank());
    };
    const int gained = rankOf(true) - rankOf(false);
    const int added = static_cast<int>(blocks.back().rows());
    if (gained < added) return {static_cast<int>(k), added - gained};
  }
  return {};
}

}  // namespace monolith::solvers
