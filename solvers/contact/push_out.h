#pragma once
// Interpenetration resolution for one central body, thesis Sec. 4.6.1 and Appendix B.
// The central body c exchanges impulses j_o with every outer body o it intersects, at the
// deepest intersection point p_o (lever arm r_o from c's centre of mass, q_o from o's), so that
// after a pseudo-time dtau the relative displacement at p_o equals d_o (the vector from the point
// on c's surface to the point on o's surface). With v_o = d_o / dtau (B.1):
//   m_c^{-1} j + r_o*^T I_c^{-1} j_tau - K_o j_o = v_o,   j = -sum j_o,  j_tau = -sum r_o* j_o.
// Cases (B.3): all dynamic -> the SPD 6x6 (3x3 in 2-D) system (B.2), Cholesky; central static ->
// independent j_d = -K_d^{-1} v_d; one static outer -> B.3.1; several statics -> B.3.2 with the
// nullspace Z of A_s (B.3.3: coincident, collinear (3-D), general), statics as the eps->0 limit of
// finite bodies with impulse factors K_hat_s.
#include <vector>

#include "solvers/contact/rigid_math.h"

namespace monolith::solvers::contact {

template <int d>
struct PushOutCentral {
  bool isStatic = false;  // infinite mass (static, kinematic or frozen)
  double mass = 1;
  AngMat<d> inertia = AngMat<d>::Identity();  // world frame
  // Length scale for the collinear/coincident rank test of B.3.3 (threshold 0.01 L^2).
  double lengthScale = 1;
};

template <int d>
struct PushOutOuter {
  bool isStatic = false;
  Vec<d> r = Vec<d>::Zero();  // c's centre of mass -> p_o
  Vec<d> q = Vec<d>::Zero();  // o's centre of mass -> p_o
  double mass = 1;            // o's mass (static: the finite mass of K_hat_s; if not
                              // finite, K_hat_s = identity as in the original code)
  AngMat<d> inertia = AngMat<d>::Identity();  // o's world inertia (static: that of K_hat_s)
  Vec<d> displacement = Vec<d>::Zero();       // d_o
};

enum class PushOutCase {
  AllDynamic = 0,        // (B.2)
  CentralStatic = 1,     // B.3 second easy case
  OneStatic = 2,         // B.3.1 (also: all statics coincident)
  StaticsCollinear = 3,  // B.3.2-B.3.3, 3-D only
  StaticsGeneral = 4,    // A_s nonsingular: statics fix the central body
};

template <int d>
struct PushOutResult {
  PushOutCase kind = PushOutCase::AllDynamic;
  Vec<d> centralDisplacement = Vec<d>::Zero();    // dtau * dv  (zero if central is static)
  AngVec<d> centralRotation = AngVec<d>::Zero();  // dtau * dw (rotation vector)
  std::vector<Vec<d>> outerImpulses;              // dtau * j_o per outer (zero for statics)
  std::vector<Vec<d>> outerDisplacements;         // dtau m_o^{-1} j_o (zero for statics)
  std::vector<AngVec<d>> outerRotations;          // dtau I_o^{-1} (q_o x j_o) (zero for statics)
};

// Solves for the push with dtau = 1 (only products dtau*v appear, so displacements come out
// directly). Requires at least one outer body.
template <int d>
PushOutResult<d> solvePushOut(const PushOutCentral<d>& central,
                              const std::vector<PushOutOuter<d>>& outers);
// The same into `result`, reusing its storage (push-out solves one such system per body and
// round; once warm this allocates nothing).
template <int d>
void solvePushOut(const PushOutCentral<d>& central, const std::vector<PushOutOuter<d>>& outers,
                  PushOutResult<d>& result);

}  // namespace monolith::solvers::contact
