#pragma once
// The implicit damping solve of Steps I and V with rigid bodies among its unknowns (thesis
// Sec. 4.7.1, 4.7.3; notes 2.5, 2.6), entity-free.
//
// Unknowns y: the velocities of the particles of one or more deformable bodies and the twists
// xi = (v, w) of the dynamic rigid bodies they are tied to. A particle is
//  * free: its velocity is an unknown;
//  * prescribed: its velocity is given (fixed particles, particles bound to static or kinematic
//    bodies, embedded particles);
//  * bound to rigid unknown c: its velocity is J_i xi_c = v_c + w_c x r_i (r_i = x_i - x_c), so
//    it is not an unknown itself: the damping force on it acts on the body through J_i^T
//    (force and torque r_i x f). Its mass is the body's already (added at scene setup);
//  * embedded in an element of another body of the solve (Sifakis et al. 2007 hard binding,
//    thesis Sec. 4.8): its velocity is sum_j w_j u_j over the element's particles, so it is not an
//    unknown either: the damping force on it acts on them with the same weights (J^T again). Its
//    mass is theirs already (moved at scene setup).
// The system is the backward Euler step of the damping alone,
//   (M - h J^T D J) y = M y0 + h J^T f,
// with M = diag(m_i, m_c, I_c) (the rigid bodies' world inertia) and J the map from the
// unknowns to every particle's velocity; J^T D J is symmetric negative semidefinite, so the
// matrix is SPD. The rigid bodies' own forces are applied by the rigid stages, so their f is 0
// here (y0 carries their current twist).
//
// Contacts enter as temporary normal joints C^T y = t (Sec. 4.7.3, "contact as temporary
// constraints"): a particle held against a static or kinematic body has its normal velocity
// prescribed (P = 1 - n n^T on it); a particle held against a rigid unknown c has its normal
// velocity relative to the body's point prescribed, n . (u_o - J_o xi_c) = t_o. The constraint
// projection is P = delta - M^{-1} C (C^T M^{-1} C)^{-1} C^T, for one body and all the particles
// held against it the central-body solve of eq. (4.3)-(4.4): with g_o = (n_o, r_o x n_o),
//   (M_c + sum_o m_o g_o g_o^T) dxi = sum_o m_o g_o (n_o . u_o - g_o . xi),
//   lambda_o = m_o (g_o . (xi + dxi) - n_o . u_o),  u_o += lambda_o n_o / m_o,  xi += dxi,
// the exact M-orthogonal projection onto that body's constraints. Each particle is held against
// one body at most, so the projections of different bodies touch disjoint unknowns and commute:
// one pass is the exact projection onto all constraints (the forward and backward sweeps of
// Sec. 4.7.3 are needed only when projections share unknowns). P is symmetric in the mass inner
// product (M P = P^T M), so CG runs on
//   P^T A P w = P^T (b - A y_p),   y = y_p + w,
// with y_p any velocity meeting the constraints (the prescribed values, t_o n_o on held
// particles, zero elsewhere), the preconditioner P M^{-1} P^T, and the product projected, so the
// residual stays in the range of P^T and the stopping test sees the projected system.
//
// The rigid unknowns' own constraints, their contacts with one another and with static and
// kinematic bodies (temporary normal-only joints, Sec. 4.7.1, 4.7.3) and their joints, are rows
// on the twists alone, G xi = t (DampingRigidRow). Together with the held particles they are one
// projection: with the held particles eliminated for a given xi' (u_o' = u_o + (g_o . xi' -
// n_o . u_o) n_o), the M-norm of the change is the K-norm about the central-body solution xi*
// (K = blockdiag(M_c + sum_o m_o g_o g_o^T)), so the exact projection is
//   xi' = xi* - K^{-1} G^T S^- G xi*,   S = G K^{-1} G^T,
// then the held particles from xi' as above. S^- is a symmetric reflexive generalized inverse
// (a box on a box: four coplanar contact points give rank 3), so the map stays an M-orthogonal
// projection (idempotent, M P = P^T M). The thesis reaches the same projection by forward and
// backward sweeps over the constraints; the sweeps give a symmetric operator but not an exact
// projection when constraints share a body (the rows here do), so the few rows of the rigid
// bodies are solved exactly instead (the matrices formed once per solve).
//
// After the solve the velocities are rebuilt from the forces at the solution, unprojected
// (Sec. 4.7.2, step 3): u_i = v_i + h (f_i + (D J y)_i) / m_i on free and held particles, and each
// rigid unknown receives the damping force of its bound particles, J_c^T D J y, returned as a
// force and torque for the caller to apply over the stage's duration. The constraints only steer
// the velocity at which the damping forces are evaluated; contact and friction follow as the
// post-process that passes momentum both ways. Since the damping forces are internal, the total
// linear momentum changes by exactly h sum f whatever CG's tolerance leaves, and with
// torque-free dampers (springs) the angular momentum is kept too.
#include <vector>

#include "solvers/contact/rigid_math.h"
#include "solvers/deformable/elasticity.h"

namespace monolith::solvers::deformable {

namespace rm = solvers::contact;

enum class ParticleRole : char { Free = 0, Prescribed = 1, Bound = 2, Embedded = 3 };

// One barycentric weight of an embedded particle (Sifakis et al. 2007 hard binding): its velocity
// is sum_j weight_j u_j over its host element's particles, in a body of the same solve.
struct EmbeddedWeight {
  int particle = 0;      // the embedded particle (in the body holding this list)
  int hostBody = 0;      // index of the host body in the solve
  int hostParticle = 0;  // a particle of the host element (free, prescribed or bound; not embedded)
  double weight = 0;
};

// One deformable body in the solve. Arrays hold d numbers per particle (m: one).
template <int d>
struct DampingBody {
  const ForceModel<d>* fm = nullptr;
  const std::vector<MatD<d>>* rotations = nullptr;  // damping rotations at x (dampingRotations)
  const double* x = nullptr;
  const double* v = nullptr;  // velocity at the start of the stage (prescribed particles: their value)
  const double* m = nullptr;
  const double* f = nullptr;  // explicit forces (ignored on prescribed and bound particles)
  std::vector<ParticleRole> role;  // per particle
  std::vector<int> rigid;          // per particle: the rigid unknown of a bound particle, else -1
  std::vector<EmbeddedWeight> embedded;  // the weights of the Embedded particles
};

// A dynamic rigid body as an unknown: mass, world inertia, centre of mass, and its twist at the
// start of the solve.
template <int d>
struct DampingRigid {
  double mass = 1;
  rm::AngMat<d> inertia = rm::AngMat<d>::Identity();
  VecD<d> x = VecD<d>::Zero();
  VecD<d> v = VecD<d>::Zero();
  rm::AngVec<d> omega = rm::AngVec<d>::Zero();
};

// A particle held along a normal: n . u = target (rigid < 0: a static or kinematic body, target
// its point's normal velocity plus what the stage keeps of the approach), or
// n . (u - v_c - w_c x r) = target (rigid >= 0: relative to that rigid unknown's point,
// r = x_particle - x_c).
template <int d>
struct DampingHold {
  int body = 0;
  int particle = 0;
  VecD<d> normal = VecD<d>::Zero();
  double target = 0;
  int rigid = -1;
};

template <int d>
using DampingTwist = Eigen::Matrix<double, d + rm::kAngularDim<d>, 1>;

// A constraint on the rigid unknowns alone: ga . xi_a + gb . xi_b = target (b = -1: on one
// unknown, the other side static, kinematic or the world, its known velocity folded into target).
// A contact at point p with normal n out of b towards a: ga = (n, r_a x n), gb = -(n, r_b x n);
// a joint's linear row n: (-n, -(r_a x n)) on the parent, (n, r_b x n) on the child; an angular
// row e: (0, -e), (0, e).
template <int d>
struct DampingRigidRow {
  int a = -1, b = -1;
  DampingTwist<d> ga = DampingTwist<d>::Zero(), gb = DampingTwist<d>::Zero();
  double target = 0;
};

struct CoupledDampingReport {
  int iterations = 0;
  double relativeResidual = 0;
  bool converged = true;
};

template <int d>
struct CoupledDampingResult {
  std::vector<std::vector<double>> u;   // per body: the rebuilt velocities (prescribed and bound: v)
  std::vector<std::vector<double>> Du;  // per body: the damping forces at the solution
  std::vector<VecD<d>> force;           // per rigid unknown: sum of the damping forces on its bound particles
  std::vector<rm::AngVec<d>> torque;    // ... and their torque about its centre of mass
  CoupledDampingReport report;
};

// The system above, assembled once; the operator and projections are exposed for tests.
template <int d>
class CoupledDampingSystem {
 public:
  CoupledDampingSystem(std::vector<DampingBody<d>> bodies, std::vector<DampingRigid<d>> rigids,
                       std::vector<DampingHold<d>> holds, double h, std::vector<DampingRigidRow<d>> rows = {});

  int size() const { return size_; }
  // A y = M y - h J^T D J y (bound components of the output zero; the input's ignored).
  void apply(const Eigen::VectorXd& in, Eigen::VectorXd& out) const;
  // The operator CG sees: P^T A P.
  void applyProjected(const Eigen::VectorXd& in, Eigen::VectorXd& out) const;
  // The projection P on a velocity (force = false) or its transpose on a force (force = true):
  // they differ only in the rigid holds' central-body solve.
  void project(Eigen::VectorXd& v, bool force) const;
  void projectVelocity(Eigen::VectorXd& y) const { project(y, false); }
  void projectForce(Eigen::VectorXd& r) const { project(r, true); }
  // The mass matrix M (for the tests' inner products) and its inverse.
  void applyMass(const Eigen::VectorXd& in, Eigen::VectorXd& out) const;
  void applyInverseMass(const Eigen::VectorXd& in, Eigen::VectorXd& out) const;
  // Constraint residuals C^T y - t (one per hold, then one per rigid row), for tests.
  std::vector<double> constraintResiduals(const Eigen::VectorXd& y) const;

  CoupledDampingResult<d> solve() const;

 private:
  int particleOffset(int body) const { return offset_[body]; }
  int rigidOffset(int c) const { return rigidStart_ + c * (d + rm::kAngularDim<d>); }
  // Expands the unknowns to every particle's velocity (bound particles from their rigid body).
  void expand(const Eigen::VectorXd& in, std::vector<std::vector<double>>& w) const;
  // The damping forces on every particle at the expanded velocities w.
  void dampingForces(const std::vector<std::vector<double>>& w, std::vector<std::vector<double>>& Dw) const;
  VecD<d> arm(int body, int particle, int c) const;
  // The central-body solution xi* of rigid unknown c and its held particles (in velocity units:
  // on forces, of M^{-1} y), and its change dxi from the twist xi.
  void centralSolution(int c, const Eigen::VectorXd& y, bool forceSide, DampingTwist<d>& xi,
                       DampingTwist<d>& dxi) const;
  // The projection of rigid unknown c and its held particles: P on velocities y, or
  // P^T = M P M^{-1} on forces; `correction` (the rigid rows' change of xi*, velocity units) or
  // null without rows.
  void projectRigidHolds(int c, Eigen::VectorXd& y, bool forceSide, const DampingTwist<d>* correction) const;

  std::vector<DampingBody<d>> bodies_;
  std::vector<DampingRigid<d>> rigids_;
  std::vector<DampingHold<d>> holds_;
  double h_;
  std::vector<int> offset_;
  int rigidStart_ = 0, size_ = 0;
  std::vector<std::vector<int>> holdsOfRigid_;  // per rigid unknown, indices into holds_
  std::vector<int> staticHolds_;
  // Per rigid unknown: the factorized (M_c + sum m_o g_o g_o^T) and the inverse world inertia.
  std::vector<Eigen::Matrix<double, d + rm::kAngularDim<d>, d + rm::kAngularDim<d>>> centralInverse_;
  std::vector<rm::AngMat<d>> inverseInertia_;
  // The rigid rows: G (rows x twists of all rigid unknowns), the correction K^{-1} G^T S^- G and
  // the particular solution map K^{-1} G^T S^- (twists x rows).
  std::vector<DampingRigidRow<d>> rows_;
  Eigen::MatrixXd rowCorrection_, rowParticular_;
  // Scratch of the operator and the projections (the solve is serial; a system is used by one
  // thread at a time), so that CG's iterations allocate nothing here.
  mutable Eigen::VectorXd scratch_, stars_, corrections_;
  mutable std::vector<std::vector<double>> expanded_, forces_;
  mutable std::vector<DampingTwist<d>> rows6_;
  mutable std::vector<double> normalSpeeds_;
};

template <int d>
CoupledDampingResult<d> solveCoupledDamping(std::vector<DampingBody<d>> bodies, std::vector<DampingRigid<d>> rigids,
                                            std::vector<DampingHold<d>> holds, double h,
                                            std::vector<DampingRigidRow<d>> rows = {});

}  // namespace monolith::solvers::deformable
