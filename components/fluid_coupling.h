#pragma once
// Two-way fluid-structure coupling (thesis Ch. 5, Sec. 5.4-5.8).
//  * FluidCoupling<d>, on a dynamic rigid body with a shape or on a deformable body: the body and
//    the scene's MAC grid fluid are solved together in one SPD system (solvers/fluid/fsi_system.h);
//    the fluid pushes the body and the body pushes the fluid. (fluid_obstacle is the one-way case: static or
//    scripted bodies, infinite mass.)
//  * FsiSolver, optional on the fluid's entity: how that system is solved.
#include <Eigen/Core>

#include <vector>

#include "components/rigid_body.h"

namespace monolith {

template <int d>
struct FluidCoupling {
  static constexpr const char* kName = "fluid_coupling";
  // Within one step only (not checkpointed): what the half-step solve (Sec. 5.4 steps 1-4) left
  // for the full solve (steps 5-7). startVelocity/startL: v^* of step 1 (v^n + dt/2 a(x^n)) as the
  // body had it; halfVelocity/halfL: what the half-step solve wrote (v^{n+1/2}); the full solve
  // takes v^* = startVelocity + (current - halfVelocity): v^n plus both half kicks of the rigid
  // pipeline (and any contact impulse between them).
  Eigen::Matrix<double, d, 1> startVelocity = Eigen::Matrix<double, d, 1>::Zero(), halfVelocity = startVelocity;
  AngularVec<d> startL = AngularVec<d>::Zero(), halfL = startL;
  // Stokes flow (no advection) keeps the structure where it is (Sec. 5.7: no structure advection).
  Eigen::Matrix<double, d, 1> startPosition = Eigen::Matrix<double, d, 1>::Zero();
  Orientation<d> startOrientation = RigidBody<d>::identityOrientation();
  bool started = false;
  // A coupled deformable body (d numbers per particle, within one step): v^n, the explicit forces
  // f(x^n) (elastic + gravity), the velocity the half-step solve wrote, x^n (Stokes keeps it).
  std::vector<double> particleStart, particleForce, particleHalf, particleStartX;
  // Scene configuration of a deformable body (not state): the particle whose position is
  // reported as fsi_<name>_track_x/_y(/_z), -1 for none.
  int trackParticle = -1;
  template <class V>
  void visitFields(V&) {}
};

struct FsiSolver {
  static constexpr const char* kName = "fsi_solver";
  enum class Preconditioner : int { None = 0, BlockJacobi = 1, BlockExact = 2, Schur = 3 };
  Preconditioner preconditioner = Preconditioner::Schur;
  bool halfStep = true;  // Sec. 5.4 steps 1-3: a coupled solve over dt/2 gives the velocity that moves the body
  // "buoyancy": "structure_cells" (false, default): a coupled rigid body feels the buoyancy of its
  // staircase, rho_f g V_cells, through the pressure; "body_volume" (true): its weight is corrected
  // by rho_f g (V_cells - V) so that weight and buoyancy together are (m - rho_f V) g for the
  // body's own volume V (systems/shape_volume.h; docs/fsi.md).
  bool bodyVolumeBuoyancy = false;
  template <class V>
  void visitFields(V& visit) {
    int p = static_cast<int>(preconditioner);
    visit("preconditioner", p);
    preconditioner = static_cast<Preconditioner>(p);
    visit("half_step", halfStep);
    visit("body_volume_buoyancy", bodyVolumeBuoyancy);
  }
};

}  // namespace monolith
