#pragma once
// The pressure jump scheme the thesis compares against (Sec. 6.4.6, after Kang, Fedkiw & Liu; the
// "Pressure Jump" column of Figs. 6.6/6.7): a one-phase free surface on a level set, surface
// tension applied explicitly as the Dirichlet pressure p = sigma kappa at the interface, with the
// second-order ghost-fluid Dirichlet condition of Gibou et al. (the thesis's Sec. 6.3.7 comparison
// discretization):
//  * kappa = div(grad phi / |grad phi|) by central differences at the cell centres (clamped to
//    1/dx), interpolated linearly to the interface;
//  * on a face between a fluid cell (phi < 0) and an air cell, the interface lies at the fraction
//    theta = phi_f / (phi_f - phi_a) of the way (clamped below at 1e-3); the pressure gradient there
//    is (p_I - p_f) / (theta dx) towards the air;
//  * the pressure Poisson equation on the fluid cells is solved directly (sparse Cholesky), walls
//    are Neumann;
//  * velocities: the air faces get values extrapolated from the fluid faces (layer averages), then
//    semi-Lagrangian advection, the projection, and phi is advected semi-Lagrangianly with the new
//    velocity, its mesh rebuilt and phi redistanced beyond `keep` cells (level_set_tracking.h).
// Used only for the stability maps; no surface mesh enters the dynamics.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "solvers/mac_layout.h"

namespace monolith::solvers {

struct PressureJumpSettings {
  double density = 1, sigma = 0;
  double blowUpSpeed = 1e3;
  double keep = 2;  // phi is redistanced beyond this many cells (level_set_tracking.h)
};

struct PressureJumpState {
  MacLayout<2> layout;
  Eigen::VectorXd u;        // face velocities
  std::vector<double> phi;  // signed distance per cell, negative in the fluid
  double time = 0;
  int step = 0;
};

struct PressureJumpReport {
  double maxSpeed = 0;  // over faces with a fluid cell on a side
  double area = 0;      // enclosed by the level set's mesh after the step
  bool blewUp = false;
  std::string blowUpReason;
};

PressureJumpReport advancePressureJump(PressureJumpState& state, const PressureJumpSettings& settings, double dt);

// Central-difference curvature of phi at every cell (stencils clamped at the sides), |kappa| <= 1/dx.
std::vector<double> levelSetCurvature(const MacLayout<2>& layout, const std::vector<double>& phi);

}  // namespace monolith::solvers
