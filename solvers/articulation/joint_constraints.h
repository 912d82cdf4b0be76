#pragma once
// Joint constraints of articulated rigid bodies in maximal coordinates, as velocity rows
// (thesis Sec. 4.4-4.7, App. C; Weinstein, Teran and Fedkiw 2006). Knows nothing of entities.
//
// A joint j between a parent a and a child b constrains, at one world point, the relative
// velocity of b against a along some linear directions n (rows n . (v_b + w_b x r_b - v_a - w_a x r_a))
// and the relative angular velocity along some angular directions e (rows e . (w_b - w_a)).
// An impulse lambda on the rows applies J = sum lambda_n n and T = sum lambda_e e: +J at the
// point and +T on b, their opposites on a. These are the columns of G_aj P_j of App. C.1 and the
// row velocities are G^T v. Post-stabilization drives the rows to a target (zero), either joint by
// joint, iterated (Gauss-Seidel, [169]), or all at once from G^T M^-1 G j = target - G^T v by
// matrix-free conjugate gradient (App. C.1.2). Unpreconditioned CG never raises the kinetic
// energy, even stopped early (App. C.1.3).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <vector>

namespace monolith::solvers {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// The joint types of components/joint.h, in the same order.
enum class JointKind : int { Fixed = 0, Revolute, Spherical, Prismatic, Universal, Twist };

// A body as the joint solves see it. Infinite mass (static, kinematic, the world): invMass 0 and
// invInertia 0; its velocities still enter the rows.
struct ConstraintBody {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  double invMass = 0;
  Eigen::Matrix3d invInertia = Eigen::Matrix3d::Zero();  // world frame
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
  Eigen::Vector3d angularImpulse = Eigen::Vector3d::Zero();  // sum of torque impulses received (adds to L)
};

// The frames and type of one joint (body-frame anchors and orientations).
struct JointDefinition {
  JointKind type = JointKind::Spherical;
  int parent = 0, child = 0;  // indices into the body list
  Eigen::Vector3d parentAnchor = Eigen::Vector3d::Zero(), childAnchor = Eigen::Vector3d::Zero();
  Eigen::Quaterniond parentFrame = Eigen::Quaterniond::Identity(), childFrame = Eigen::Quaterniond::Identity();
  bool limited = false;  // revolute, twist: angle limits [lower, upper]
  double lower = 0, upper = 0;
  bool slideLimited = false;  // prismatic, twist: slide limits [slideLower, slideUpper] along the axis
  double slideLower = 0, slideUpper = 0;
  // A joint of the plane z = 0 between bodies that move in it (2-D scenes): its frames turn about
  // z only, and the rows that leave the plane (linear along z, angular about x and y) are dropped;
  // a pin is then a revolute joint about z, a 2-D slider a prismatic joint along an in-plane z.
  bool planar = false;
};

// A joint's rows at given poses.
struct JointRows {
  int parent = 0, child = 0;
  Eigen::Vector3d armParent = Eigen::Vector3d::Zero(), armChild = Eigen::Vector3d::Zero();  // to the child's anchor
  int linear = 0, angular = 0;                           // row counts (linear rows first)
  Eigen::Matrix3d linearDirs = Eigen::Matrix3d::Zero();  // columns, world
  Eigen::Matrix3d angularDirs = Eigen::Matrix3d::Zero();
  int rows() const { return linear + angular; }
};

// Position error of a joint at given poses, as world vectors with the free components removed:
// the child's anchor minus the parent's, and the rotation vector that turns the parent's joint
// frame onto the child's (Sec. 4.5.1: the vector part of q_c q_p^-1, sign-fixed so the scalar
// part is positive, without the free twist of a revolute joint, plus how far a limited one is
// past its limit, along the hinge). For a universal joint the angular error is along the common
// normal of the two axes.
struct JointError {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();
};

// A limited revolute joint gains a third angular row (the hinge axis) while its angle is past a
// limit, or within limitSlack of it and turning further out with the bodies' velocities.
JointRows jointRows(const JointDefinition& joint, const std::vector<ConstraintBody>& bodies);
inline constexpr double limitSlack = 1e-9;
JointError jointError(const JointDefinition& joint, const Eigen::Vector3d& xParent, const Eigen::Quaterniond& qParent,
                      const Eigen::Vector3d& xChild, const Eigen::Quaterniond& qChild);
// Angle of a revolute joint: the child's frame turned about the parent frame's z axis, in (-pi, pi].
double revoluteAngle(const JointDefinition& joint, const Eigen::Quaterniond& qParent, const Eigen::Quaterniond& qChild);
// The parent joint frame's z axis in the world (a revolute joint's hinge).
Eigen::Vector3d jointAxis(const JointDefinition& joint, const Eigen::Quaterniond& qParent);

// G^T v for one joint (its rows' relative velocities).
Vector6d rowVelocities(const JointRows& rows, const std::vector<ConstraintBody>& bodies);
// Applies a row impulse (M^-1 G_j lambda) to the bodies' velocities.
void applyRowImpulse(const JointRows& rows, const Vector6d& lambda, std::vector<ConstraintBody>& bodies);
// G_j^T M^-1 G_j (rows x rows, in the top-left corner).
Eigen::Matrix<double, 6, 6> effectiveMass(const JointRows& rows, const std::vector<ConstraintBody>& bodies);
// A row's velocity expressed as a world 6-vector [linear; angular] projected on the rows.
Vector6d rowsOf(const JointRows& rows, const Eigen::Vector3d& linear, const Eigen::Vector3d& angular);

// max_i<n |v_i|.
double largestEntry(const Vector6d& v, int n);

struct ProjectionReport {
  int iterations = 0;           // sweeps (pairwise) or CG iterations (global)
  double residual = 0;          // largest |row velocity - target| left
};

// Gauss-Seidel over the joints in order: each joint's rows set to their target exactly, sweeps
// repeated until every row is within tolerance or maxSweeps is reached.
ProjectionReport projectPairwise(const std::vector<JointRows>& joints, const std::vector<Vector6d>& targets,
                                 std::vector<ConstraintBody>& bodies, int maxSweeps, double tolerance);
// App. C.1: G^T M^-1 G lambda = target - G^T v by unpreconditioned CG (matrix-free), then
// v += M^-1 G lambda. Stops when every row is within tolerance or after maxIterations.
ProjectionReport projectGlobal(const std::vector<JointRows>& joints, const std::vector<Vector6d>& targets,
                               std::vector<ConstraintBody>& bodies, int maxIterations, double tolerance);

// The first joint (in order) that closes a loop whose rows depend on the rows of the joints
// before it -- a loop that over-constrains its bodies, such as a ring of fixed joints, a planar
// ring of hinges with parallel axes, or a spherical joint closing a rigid ring -- with how many
// of its rows are redundant; -1 when there is none. Bodies of zero inverse mass (static,
// kinematic, the world) are one immovable node. Rows of revolute limits are left out (they
// are one-sided and come and go). Only joints that close a loop are tested: a joint that adds a
// body to a tree never repeats a row.
struct RedundantJoint {
  int joint = -1;
  int redundantRows = 0;
};
RedundantJoint firstRedundantJoint(const std::vector<JointDefinition>& joints, const std::vector<ConstraintBody>& bodies);

// Where a body will be after Step IV with its current velocity (the caller's own rule).
using PosePredictor = std::function<void(int body, const ConstraintBody&, Eigen::Vector3d& x, Eigen::Quaterniond& q)>;

// Pre-stabilization (Step III.3): impulses on the velocities so that the poses they lead to
// satisfy the joints. Pairwise: Newton per joint in order ([169] with the quaternion-product
// error of Sec. 4.5.1), sweeps repeated. Global (App. C.2): the desired relative velocities
// -error/dt of all joints as the target of one global projection, Newton iterated.
// The rows (Jacobian) are those of the current poses. Returns the largest error left (m, rad).
struct PreStabilizationReport {
  int iterations = 0;
  double errorBefore = 0, errorAfter = 0;
};
PreStabilizationReport preStabilize(const std::vector<JointDefinition>& joints, std::vector<ConstraintBody>& bodies,
                                    const PosePredictor& predict, double dt, bool global, int maxIterations,
                                    double tolerance);

// Moves the bodies so that the joints close at their current poses (not in the thesis; after
// interpenetration resolution, which moves bodies one contact at a time and may pull joints
// apart): pre-stabilization's Newton with displacements in place of velocities (dt = 1, poses
// x + dx, exp(dw*) q), mass-weighted, so the centre of mass stays put. Velocities are untouched.
PreStabilizationReport closeJoints(const std::vector<JointDefinition>& joints, std::vector<ConstraintBody>& bodies,
                                   bool global, int maxIterations, double tolerance);

}  // namespace monolith::solvers
