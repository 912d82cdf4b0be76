#pragma once
// Fluid-structure coupling operators of thesis Sec. 5.4 (eq. 5.8-5.12), knowing nothing of
// entities:
//
//  * W: one coupling constraint per listed velocity unknown (a 0/1 restriction, W W^T = I);
//  * J = N J_hat R: structure degrees of freedom -> normal velocity at each constrained face.
//      R (samples*d x structure dofs): for a rigid body one sample per face at the face centre,
//        R_pb = (I  r*^T) so that v_p = v + w x r (eq. 5.10); for deformable particles R = I;
//      J_hat (faces*d x samples*d): blocks alpha_fp I with sum_p alpha_fp = 1 (interpolation);
//      N (faces x faces*d): N_ff = n_f^T (the face's axis).
//    Any structure that supplies R, J_hat and its mass plugs in here unchanged: the rigid path
//    below builds R with rigidSampleRows and J_hat = I; particles give R = I and their weights.
//  * M, M^{-1}: the structure's mass (block diagonal; a rigid body's block is diag(m) and its
//    world inertia).
//
// Domain walls, static and scripted obstacles are structures of infinite mass: their M^{-1} = 0
// makes the constraint u_f = J v a known value, which is how the fluid operators already treat
// them (prescribed faces). Only finite-mass structures are listed here.
//
// The coupling faces are fluid velocity unknowns (they keep their dual cell's fluid mass beta,
// Sec. 5.4.2): the faces between a fluid cell and a structure cell, and, with viscosity, the
// faces inside a structure that are viscous neighbours of a fluid face (Sec. 5.7, Fig. 5.2: they
// carry the tangential coupling).
#include "solvers/fluid/operators.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <vector>

namespace monolith::solvers {

struct StructureCoupling {
  std::vector<int> constrainedVelocities;  // W: per constraint the velocity unknown it acts on
  std::vector<int> constrainedFaces;       // the same faces as layout face indices
  SparseMatrixR J;                          // constraints x structure dofs (= N J_hat R)
  SparseMatrixR massInverse;                // M^{-1}
  SparseMatrixR mass;                       // M (kinetic energy of the structure)
  Eigen::VectorXd velocity;                 // v* on input to a solve, v^{n+1} after it
  // C, the structure's factored damping over the solve's dt (Sec. 5.5.1: C^T C = -dt D, rows of
  // K = [0, C] in (5.30)); dampingRows == 0: undamped (rigid bodies). Both act on whole
  // structure vectors: y = C v (dampingRows entries) and f = C^T y (structureCount entries).
  int dampingRows = 0;
  std::function<void(const Eigen::VectorXd& v, Eigen::VectorXd& y)> damping;
  std::function<void(const Eigen::VectorXd& y, Eigen::VectorXd& f)> dampingTranspose;

  int constraintCount() const { return static_cast<int>(constrainedVelocities.size()); }
  int structureCount() const { return static_cast<int>(velocity.size()); }
};

// The number of velocity degrees of freedom of one rigid body: 3 in 2-D (v, w_z), 6 in 3-D.
constexpr int rigidDofs(int d) { return d == 2 ? 3 : 6; }

// Rows of R for one rigid sample point at offset r = x_p - c from the body's centre of mass, as
// triplets into a (samples*d x structure dofs) matrix: sample `sample`, body dofs from
// `dofOffset` (v first, then w; 2-D: w_z only).
template <int d>
void rigidSampleRows(int sample, int dofOffset, const Eigen::Matrix<double, d, 1>& r,
                     std::vector<Eigen::Triplet<double>>& out);

// N for the constrained faces of `layout`: row k has a 1 at column k*d + axis(face k).
template <int d>
SparseMatrixR faceNormalRows(const MacLayout<d>& layout, const std::vector<int>& faces);

// Makes `structureCells` (cell mask, != 0: inside a finite-mass structure) part of the domain as
// structure: those cells are Solid, the faces between such a cell and a fluid cell become free
// velocity unknowns, and with `viscous` so do the faces inside the structure that are viscous
// pair neighbours of a free fluid face; every other face touching a structure cell becomes
// Inactive. Returns the coupling faces (layout face indices, ascending). Faces that a wall, an
// inflow or a prescribed obstacle already fixes stay prescribed (infinite mass wins); a coupling
// face that a cut-cell obstacle covers in part (domain.openFraction) becomes whole: the structure
// covers it, and the coupling constraint acts on the whole face.
// Sets domain.structureFace so that the viscous operator drops the rows between two coupling
// faces (both move with rigid structure; no fluid shear between them).
template <int d>
std::vector<int> markStructure(FluidDomain<d>& domain, const std::vector<std::uint8_t>& structureCells, bool viscous);

}  // namespace monolith::solvers
