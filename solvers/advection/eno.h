#pragma once
// Third-order Hamilton-Jacobi ENO convection with third-order TVD Runge-Kutta time integration:
// the advection of thesis Ch. 6 (eq. 6.3: "3rd order Runge Kutta [135] and 3rd order Hamilton
// Jacobi ENO [116]"), in the form of Osher & Fedkiw, "Level Set Methods and Dynamic Implicit
// Surfaces", Sec. 3.3 (divided-difference ENO) and Shu & Osher 1988 (TVD RK3).
//
// Spatial operator, for each face component u_a (or a cell-centred scalar phi):
//     (w . grad) u_a ~= sum_b w_b D_b^{-/+} u_a,
// with the one-sided ENO3 derivative D_b^- if w_b > 0, D_b^+ if w_b < 0 (upwinding), taken along
// axis b on the grid on which the component lives. w is the velocity at that sample point:
// w_a = u_a itself; the other components are interpolated to the face (resp. cell centre) with
// the 4th-order midpoint rule (-1, 9, 9, -1)/16 per half-offset axis, because the simple
// 2-/4-point average is only 2nd order and would cap the convective term at 2nd order; near
// walls, structures or prescribed faces (stencil not fully in the interior fluid) it falls back
// to FaceVelocitySampler (multilinear with the rules of velocity_sampling.h).
//
// Ghost values (the stencil reaches 3 nodes beyond the point):
//   * periodic axes wrap;
//   * across a non-periodic domain wall the value of the last stored node is repeated
//     (zero-gradient extrapolation). The wall-normal velocity vanishes at a wall, so the upwind
//     weight of the wall-normal derivative is O(dx) there and this O(1)-gradient error enters the
//     convective term only at O(dx) in the first cells (first order at walls, as the thesis'
//     Sec. 5.4 wall treatment);
//   * prescribed faces (walls, coupling faces, faces inside structures) are read as their
//     prescribed velocity, i.e. the structure velocity is the ghost extension into obstacles,
//     or, where the boundary has ghost rules (wall at the obstacle's surface), as the linear
//     extension through that wall (velocity_sampling.h, rule 3b);
//     ENO's smoothest-stencil choice then prefers stencils away from the velocity kink.
// Prescribed faces get a zero convective term and keep their prescribed value.
//
// Time integration (Shu-Osher TVD RK3) of u_t = L(u) = -(u . grad) u, the stage velocity being
// used for upwinding in each stage:
//     u1 = u + dt L(u);  u2 = 3/4 u + 1/4 (u1 + dt L(u1));  u^{n+1} = 1/3 u + 2/3 (u2 + dt L(u2)).
// Stable for Courant numbers sum_b |w_b| dt / dx up to about 1 (the thesis uses CFL 0.9,
// Sec. 5.11); note dt = cfl dx / max|u| (cfl.h) allows a summed Courant number of d * cfl.
//
// Parallel over faces (cells) with tbb::parallel_for, each output written once: bitwise
// independent of the thread count.
#include "solvers/advection/velocity_sampling.h"
#include "solvers/mac_layout.h"

#include <Eigen/Core>
#include <array>

namespace monolith::solvers {

// The one-sided derivative rule of the Hamilton-Jacobi schemes below.
//  * Eno3: third-order ENO (the thesis' scheme). Its stencil choice is a discontinuous function
//    of the data, so a steady flow can settle into a limit cycle of stencil switches (measured
//    on DFG 2D-1: a period-4 cycle of 1e-3 beside the disk, docs/benchmarks.md).
//  * Weno5: fifth-order weighted ENO (Jiang & Peng 2000; Osher & Fedkiw Sec. 3.4) on the same
//    six points: a convex combination of the three ENO3 candidates whose weights are smooth in
//    the data, fifth order where the solution is smooth and ENO-like at kinks; its steady
//    states exist and are reached.
enum class HjStencil { Eno3, Weno5 };

// ENO3 one-sided derivative at v[3] from the seven values v[0..6] at spacing dx: backward
// (D^-, upwind for positive velocity; uses v[0..5]) or forward (D^+; uses v[1..6]).
// Exact for cubic polynomials.
double eno3Derivative(const std::array<double, 7>& v, double dx, bool backward);

// WENO5 one-sided derivative at v[3], same arguments and stencils (D^- uses v[0..5], D^+ v[1..6]).
// Exact for cubics (every candidate is); fifth order on smooth data.
double weno5Derivative(const std::array<double, 7>& v, double dx, bool backward);

// (u . grad) u at every face (component of the face's axis); 0 on prescribed faces.
template <int d>
Eigen::VectorXd enoConvectiveTerm(const MacLayout<d>& layout, const Eigen::VectorXd& u,
                                  const FaceBoundary& boundary = {}, HjStencil stencil = HjStencil::Eno3);

// One TVD-RK3 step of u_t + (u . grad) u = 0 (no pressure). dt >= 0 and finite.
template <int d>
Eigen::VectorXd advectFacesEnoRk3(const MacLayout<d>& layout, const Eigen::VectorXd& u, double dt,
                                  const FaceBoundary& boundary = {}, HjStencil stencil = HjStencil::Eno3);

// (u . grad) phi for a cell-centred scalar phi (one value per cell, layout.cellIndex order) in
// the face-velocity field u. Solid cells get 0 (their values are only read, as ghost values).
template <int d>
Eigen::VectorXd enoScalarConvectiveTerm(const MacLayout<d>& layout, const Eigen::VectorXd& phi,
                                        const Eigen::VectorXd& u, const FaceBoundary& boundary = {},
                                        HjStencil stencil = HjStencil::Eno3);

// One TVD-RK3 step of phi_t + (u . grad) phi = 0 with u frozen over the step.
template <int d>
Eigen::VectorXd advectScalarEnoRk3(const MacLayout<d>& layout, const Eigen::VectorXd& phi,
                                   const Eigen::VectorXd& u, double dt, const FaceBoundary& boundary = {},
                                   HjStencil stencil = HjStencil::Eno3);

}  // namespace monolith::solvers
