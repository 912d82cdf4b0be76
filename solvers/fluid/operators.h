#pragma once
// Volume-weighted MAC operators of thesis Ch. 5 on the free degrees of freedom of a FluidDomain:
//
//  * pressure unknowns: Fluid cells (Dirichlet cells and ghosts outside Outflow sides have p = 0);
//  * velocity unknowns: Free faces; Prescribed faces are known and move to right-hand sides;
//  * G (velocity unknowns x pressure unknowns): (G p)_f = A (p(upper cell) - p(lower cell)), the
//    volume-weighted gradient, = -D^T with D the area-weighted divergence (Sec. 5.2, 5.4.2);
//  * beta^-1 = 1 / (rho V_cell) per face (constant density, Sec. 5.4.2);
//  * G_mu (Sec. 5.7, notes 4.3): one row per pair of neighbouring same-axis faces (f, f + e_b),
//    w (u(f + e_b) - u(f)) with w = sqrt(dt mu / V_cell) A, so that beta^-1 G_mu^T G_mu is
//    -dt nu times the 5-/7-point Laplacian of each velocity component.
//
// Cut faces (domain.openFraction, boundary.h): a free face with open fraction theta has area
// theta A in G and D and mass theta rho V_cell in beta, so the velocity update beta^-1 G p is the
// plain pressure difference while the divergence counts only the open part of the face; its covered
// part moves with the obstacle and enters g. This is the variational cut-cell discretization of Ng,
// Min & Gibou (2009), which keeps (5.31) symmetric positive definite. For G_mu a cut face whose
// centre lies inside the obstacle (wallDistance 0, boundary.h) is the obstacle's wall, as in Ng, Min
// & Gibou's viscous step, where such faces take the solid's velocity: a pair from an outside face
// into it is a wall row w (U - u_f) / sqrt(theta), theta the distance to the surface between the two
// (as for a covered face), and the face itself has the one row w (U - u) / sqrt(kMinWallDistance)
// (U the obstacle's velocity there), which holds it to the body while the pressure still acts on
// its open part. Without it the face was an ordinary unknown a cell away from its neighbours, so
// the wall they saw moved with where the surface cut the faces (Couette torque 2-4 % off, jumping
// with the grid; 0.05-0.13 % with it). The rows keep the G_mu^T G_mu form: SPD. Rows of outside
// cut faces are not weighted by their open fractions (beta^-1 G_mu^T G_mu is 1/theta times the
// point Laplacian there; weighting them made the Couette torque converge at first order, 2.8 %
// off at 32 cells and 0.6 % at 128, worse than without).
//
// Known values enter as affine terms: the discrete divergence of a full velocity field is
// D u = -G^T u_free + g (g = prescribed-face fluxes, `prescribedDivergence`), and the viscous row
// values are G_mu u_free + h (`viscousKnown`).
//
// Domain-side tangential conditions for G_mu (pairs that cross a side along b != face axis):
//  * Dirichlet (no-slip wall with wall velocity U, or inflow): the ghost face outside is mirrored,
//    u_ghost = 2U - u_f, so the wall value is met at the wall (second order; linear profiles such as
//    Couette flow are reproduced exactly). The consistent factor of that boundary term is the row
//    sqrt(2) w (U - u_f): its contribution to G_mu^T G_mu, 2 w^2 (u_f - U), is exactly the mirrored
//    ghost's contribution w^2 (u_f - u_ghost) to the Laplacian, keeping the system symmetric.
//  * slip wall / outflow: zero shear, the row is dropped (notes 4.3: missing neighbour -> no row).
// Pairs along the face axis that leave the box are dropped too (beyond a wall or inflow face both
// values are known; beyond an outflow face the normal velocity has zero normal derivative).
// Pairs with a prescribed face inside the box (obstacle, wall normal face) are Dirichlet at the
// face itself (first order at obstacles, as Sec. 5.7 says of its constraint locations), unless the
// domain carries wallDistance: then a pair ending on an obstacle face puts the wall at the
// obstacle's true surface, theta cells away along the pair (row weight w / sqrt(theta); theta = 1/2 is the
// mirrored domain-wall ghost above). This is Gibou et al.'s symmetric Dirichlet treatment (J.
// Comput. Phys. 176, 2002): second order for the wall shear instead of the staircase's first.
#include "solvers/fluid/boundary.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <vector>

namespace monolith::solvers {

using SparseMatrixR = Eigen::SparseMatrix<double, Eigen::RowMajor>;

struct FluidParameters {
  double density = 1;    // rho
  double viscosity = 0;  // dynamic viscosity mu (0: no G_mu rows at all)
  double dt = 1;
};

// Numbering of the unknowns. -1 marks "not an unknown".
struct FluidDofs {
  std::vector<int> cellToPressure, pressureToCell;
  std::vector<int> faceToVelocity, velocityToFace;
  // Per pressure unknown: id of its connected region (cells linked by free faces) if that region
  // touches no Dirichlet value, i.e. the constant on it is in the null space of G; else -1.
  std::vector<int> closedComponent;
  int closedComponentCount = 0;

  int pressureCount() const { return static_cast<int>(pressureToCell.size()); }
  int velocityCount() const { return static_cast<int>(velocityToFace.size()); }
};

// One row of G_mu: c0 u[u0] + c1 u[u1] (+ the known part in viscousKnown); u0/u1 are velocity
// unknowns or -1 when that end is known.
struct ViscousRow {
  int u0 = -1, u1 = -1;
  double c0 = 0, c1 = 0;
};

template <int d>
struct FluidOperators {
  FluidDomain<d> domain;  // a copy: the operators stay valid when the caller's domain changes
  FluidParameters params;
  FluidDofs dofs;
  double area = 0, volume = 0;
  double betaInv = 0;        // 1 / (rho V_cell): a whole face; a cut face has betaInv / theta
  bool cut = false;          // some free face is cut (openFraction != 1)
  Eigen::VectorXd openFraction;  // theta per velocity unknown (all 1 without cut faces)
  Eigen::VectorXd faceBetaInv;   // betaInv / theta per velocity unknown (built once, used per solve)
  double viscousWeight = 0;  // w = sqrt(dt mu / V_cell) A

  // Stencil tables for the matrix-free applies.
  std::vector<std::array<int, 2>> gradientCells;       // per velocity unknown: pressure unknown below/above
  std::vector<std::array<int, 2 * d>> divergenceFaces; // per pressure unknown: [2a] lower, [2a+1] upper face
  std::vector<ViscousRow> viscousRows;
  std::vector<std::array<int, 2 * d>> faceViscousRows; // per velocity unknown: [2b] row where it is u1,
                                                       // [2b+1] row where it is u0 (-1: none)
  Eigen::VectorXd prescribedDivergence;  // g (per pressure unknown)
  Eigen::VectorXd viscousKnown;          // h (per viscous row)

  // The same operators assembled (for IC(0), tests and inspection).
  SparseMatrixR G;    // velocity unknowns x pressure unknowns
  SparseMatrixR Gmu;  // viscous rows x velocity unknowns

  int pressureCount() const { return dofs.pressureCount(); }
  int velocityCount() const { return dofs.velocityCount(); }
  int viscousCount() const { return static_cast<int>(viscousRows.size()); }
};

template <int d>
FluidDofs numberFluidDofs(const FluidDomain<d>& domain);

template <int d>
FluidOperators<d> buildFluidOperators(const FluidDomain<d>& domain, const FluidParameters& params);

// Matrix-free applies, parallel over output rows (each row written by one task: deterministic).
template <int d>
void applyGradient(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> out);
template <int d>  // G^T u = -(D u) on the unknown cells, free faces only
void applyGradientTranspose(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& u,
                            Eigen::Ref<Eigen::VectorXd> out);
template <int d>
void applyViscousGradient(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& u,
                          Eigen::Ref<Eigen::VectorXd> out);
template <int d>
void applyViscousGradientTranspose(const FluidOperators<d>& ops, const Eigen::Ref<const Eigen::VectorXd>& r,
                                   Eigen::Ref<Eigen::VectorXd> out);

// Full face vector <-> velocity unknowns. writeVelocities sets free faces from `free`, prescribed
// faces to their prescribed velocity, and leaves inactive faces unchanged.
template <int d>
Eigen::VectorXd freeVelocities(const FluidOperators<d>& ops, const Eigen::VectorXd& faceVelocities);
template <int d>
void writeVelocities(const FluidOperators<d>& ops, const Eigen::VectorXd& free, Eigen::VectorXd& faceVelocities);

// beta^-1 per velocity unknown (1 / (rho V_cell theta)).
template <int d>
const Eigen::VectorXd& faceBetaInverse(const FluidOperators<d>& ops) {
  return ops.faceBetaInv;
}

// The constraint the projection drives to zero, per pressure unknown: (D u)_c = -G^T u_free + g,
// cut faces weighted by their open fractions and their covered parts moving with the obstacle.
template <int d>
Eigen::VectorXd constraintDivergence(const FluidOperators<d>& ops, const Eigen::VectorXd& faceVelocities);

// Volume-weighted divergence (D u)_c = sum over the cell's faces of +-A u, over every face of every
// cell (prescribed ones included, periodic wrap applied): the quantity projection drives to zero.
template <int d>
Eigen::VectorXd volumeDivergence(const MacLayout<d>& layout, const Eigen::VectorXd& faceVelocities);

// Assembled Poisson block G^T beta^-1 G (pressure unknowns; the (5.31) top-left block).
template <int d>
SparseMatrixR assemblePoisson(const FluidOperators<d>& ops);
// Assembled (5.31) matrix [[G^T b G, G^T b G_mu^T], [G_mu b G, I + G_mu b G_mu^T]], b = beta^-1.
template <int d>
SparseMatrixR assembleCoupled(const FluidOperators<d>& ops);

}  // namespace monolith::solvers
