#pragma once
// Normal-only contact of one central rigid body with all the particles touching it at once,
// thesis Sec. 4.7.3 "Rigid/deformable contact", eq. (4.3)-(4.4) (notes 2.6). Each outer particle o
// (mass m_o, no rotation: q_o = 0, K_o = m_o^{-1} delta) at arm r_o from the body's centre of mass
// receives an impulse lambda_o n_o along its normal, the body the opposite -lambda_o n_o at r_o,
// such that the relative normal velocity u_o . n_o (particle minus body point) becomes the target
// (zero: contact is inelastic). With the body's velocity change dxi = (dv, dw) and g_o = (n_o,
// r_o x n_o), lambda_o = m_o (target_o - u_o.n_o + g_o . dxi), and the body's momentum balance
// M_c dxi = -sum lambda_o g_o gives the symmetric positive definite 6x6 (3x3 in 2-D) system
//   (M_c + sum_o m_o g_o g_o^T) dxi = sum_o m_o (u_o.n_o - target_o) g_o,          (4.4)
// M_c = diag(m_c delta, I_c) the body's mass and world inertia (L_o = m_o n_o n_o^T is the thesis's
// (n^T K_o n)^{-1} n n^T). Contact only pushes: a particle whose lambda would be negative leaves
// the active set, one that would approach after the body's change joins it, and the system is
// solved again (a small active-set loop). A static or kinematic central body (infinite inertia)
// decouples: lambda_o = m_o (target_o - u_o.n_o) for approaching particles.
#include <vector>

#include "solvers/contact/rigid_math.h"

namespace monolith::solvers::contact {

template <int d>
struct CentralNormalBody {
  bool infinite = false;  // static or kinematic (or frozen): takes no impulse
  double mass = 1;
  AngMat<d> inertia = AngMat<d>::Identity();  // world frame
};

template <int d>
struct CentralNormalOuter {
  double mass = 1;
  Vec<d> r = Vec<d>::Zero();  // body's centre of mass -> contact point
  Vec<d> n = Vec<d>::Zero();  // unit normal out of the body
  double normalVelocity = 0;  // u_o . n_o: particle velocity minus the body's point velocity
  double target = 0;          // wanted relative normal velocity
};

template <int d>
struct CentralNormalResult {
  std::vector<double> lambda;  // impulse on each particle along its n (>= 0); the body gets the opposite
  Vec<d> bodyImpulse = Vec<d>::Zero();          // -sum lambda_o n_o
  AngVec<d> bodyAngularImpulse = AngVec<d>::Zero();  // -sum lambda_o r_o x n_o
  int active = 0;   // particles with lambda > 0
  int solves = 0;   // linear solves of the active-set loop
};

template <int d>
CentralNormalResult<d> solveCentralNormalContact(const CentralNormalBody<d>& body,
                                                 const std::vector<CentralNormalOuter<d>>& outers);

}  // namespace monolith::solvers::contact
