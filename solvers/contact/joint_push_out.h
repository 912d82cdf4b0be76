#pragma once
// Interpenetration resolution for several bodies at once (not in the thesis). The
// thesis's push-out (push_out.h, App. B) moves one central body against all the bodies it
// overlaps, level by level. In a jam -- a body wedged between two others that are themselves
// pressed against a third or a wall -- each such solve pushes its body into a neighbour the
// solve does not move, and push-out's later rounds are undone (push_out_rounds.h): without this
// solve 2-D random drops keep overlaps of 10-60 % of a thin body's size for a step.
//
// Here every body of the jam moves together: the smallest mass-weighted displacement
//   min sum_i (m_i |dx_i|^2 + dtheta_i . I_i dtheta_i)
//   subject to n_c . (dx_a + dtheta_a x r_a - dx_b - dtheta_b x r_b) >= depth_c for every point c,
// linearised at the current poses. Its optimality conditions are those of a contact problem in
// "position impulses" lambda_c >= 0 with dx = M^{-1} J^T lambda, solved by projected
// Gauss-Seidel on lambda (complementarity: lambda_c > 0 only where the constraint is tight). A
// body of infinite mass (static, kinematic, or a dynamic body outside the jam) is a fixed
// partner. The caller re-measures the geometry and repeats, since rotations are linearised.
#include <vector>

#include "solvers/contact/rigid_math.h"

namespace monolith::solvers::contact {

template <int d>
struct JointBody {
  double inverseMass = 0;
  AngMat<d> inverseInertia = AngMat<d>::Zero();  // world frame
};

template <int d>
struct JointPoint {
  int a = -1, b = -1;         // indices into the bodies; -1: a fixed partner
  Vec<d> ra = Vec<d>::Zero();  // a's centre -> the point (unused for a fixed partner)
  Vec<d> rb = Vec<d>::Zero();  // b's centre -> the point
  Vec<d> n = Vec<d>::Zero();   // unit, out of b towards a
  double depth = 0;            // separation to gain along n (> 0)
};

template <int d>
struct JointMove {
  Vec<d> dx = Vec<d>::Zero();
  AngVec<d> dtheta = AngVec<d>::Zero();  // rotation vector (2-D: angle)
};

// The moves of `bodies` (resized to match) after Gauss-Seidel sweeps over the points in their
// order, until no point's separation changes by more than `tolerance` (metres) in a sweep, or
// after `sweeps`; deterministic. Returns the largest constraint violation left (metres, >= 0).
template <int d>
double solveJointPushOut(const std::vector<JointBody<d>>& bodies, const std::vector<JointPoint<d>>& points, int sweeps,
                         double tolerance, std::vector<JointMove<d>>& moves);

}  // namespace monolith::solvers::contact
