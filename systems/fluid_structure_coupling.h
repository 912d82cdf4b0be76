#pragma once
// Two-way coupling of dynamic rigid bodies and deformable bodies (fluid_coupling) with the scene's
// MAC grid fluid in one SPD solve (thesis Sec. 5.4-5.8, eq. 5.30; solvers/fluid/fsi_system.h). The FSI time step of
// Sec. 5.4 maps onto the pipeline as:
//   1. v^* = v^n + dt/2 a(x^n)        advance_rigid_velocity_half (Step I of the rigid pipeline)
//   2-3. fsi_half_step (Stage I, after it): u^ = u^n + dt/2 g and the coupled solve over dt/2 at
//        x^n; its structure velocity v^{n+1/2} replaces the body's velocity, its fluid is discarded
//   4. x^{n+1} = x^n + dt v^{n+1/2}    advance_rigid_positions (Step IV)
//   5. v^* = v^n + dt/2 (a(x^n) + a(x^{n+1}))   advance_rigid_velocity (Step V) + what fsi_half_step kept
//   6. u^* = u^n - dt (u.grad)u + dt g          advect_fluid, fluid_gravity
//   7. project_fluid_structure (Step V): the coupled solve at x^{n+1} gives u^{n+1}, v^{n+1}.
// Without the half step (fsi_solver "half_step": false) step 4 moves the body with the rigid
// pipeline's v^n + dt/2 a.
// A coupled deformable body takes the same steps with its particles (its own Newmark systems skip
// it): v^* = v^n + dt/2 M^-1 f(x^n) with f the explicit elastic forces and gravity, the half-step
// solve with its damping over dt/2, and v^* = v^n + dt/2 M^-1 (f(x^n) + f(x^{n+1})) for the full
// solve, whose damping is backward Euler over dt (C in the system, Sec. 5.5.1). Its structure
// cells are the cells whose centre lies in an element; J interpolates the particle velocities
// barycentrically to the coupling face centres (R = I, J_hat = the weights, Sec. 5.4.3). In Stokes flow (advection "none") the structure is not advected
// (Sec. 5.7): its pose stays at x^n.
//
// The structure cells are the cells whose centres lie inside a coupled body (staircase, Sec.
// 5.4.1); the coupling faces and J = N J_hat R are built afresh at every solve from the bodies'
// poses (solvers/fluid/structure_coupling.h). Reports per coupled body (entity name N):
// fsi_N_position_x/_y(/_z), fsi_N_velocity_x/_y(/_z), fsi_N_angular_velocity(_z or _x/_y/_z), and the fluid's force and
// torque on it from the coupling impulses, fsi_N_force_x/... = -(J^T W^T lambda)/dt; and per
// step fsi_solver_iterations, fsi_half_step_iterations, fsi_energy_change (kinetic energy after
// minus before the full solve, <= 0 up to rounding, Sec. 5.8), fsi_half_step_energy_change.
#include "components/fluid_coupling.h"
#include "components/mac_grid.h"
#include "ecs/system.h"
#include "solvers/fluid/fsi_system.h"
#include "solvers/fluid/simplex_interpolation.h"
#include "systems/deformable_dynamics.h"

namespace monolith {

// The structure part of one coupled solve, built at the structures' current poses.
template <int d>
struct StructureCouplingSetup {
  solvers::FluidDomain<d> domain;       // the grid's domain with the structure cells marked
  // W, J, M, M^-1, v and C: the rigid bodies' dofs first (3 or 6 each, in `bodies` order), then
  // each deformable's particle velocities (d each, from deformableOffset[k]).
  solvers::StructureCoupling coupling;
  std::vector<Entity> bodies;           // rigid
  std::vector<Entity> deformables;
  std::vector<int> deformableOffset;
  std::vector<solvers::SimplexLocator<d>> locators;                 // per deformable, at its x
  std::vector<const solvers::deformable::ForceModel<d>*> models;    // per deformable
  std::vector<std::vector<solvers::deformable::MatD<d>>> rotations; // per deformable (damping)
  std::vector<std::vector<double>> positions;                       // per deformable: x
  std::vector<int> dampingOffset;                                   // per deformable: first row of C
  std::vector<int> cellBody;  // per cell: rigid index, bodies.size() + deformable index, or -1
  // J with the rows of fixed particles and static bodies kept (J zeroes them: infinite mass, at
  // rest): J_all^T lambda is the impulse on every structure dof, so the force reported on a body
  // includes what its fixed parts pass on to their support (a clamped flag's root, a fixed
  // cylinder). Empty when there are neither.
  solvers::SparseMatrixR forceJ;
};

// Builds the setup for `grid` from every entity with fluid_coupling and either a rigid_body with
// a shape (or level set) or a deformable body. The structure velocity is read from the bodies
// (v, w = I^-1 L) and particles. `viscous`: the fluid has viscosity. The damping factor C is
// attached for a solve over `dt` (C^T C = -dt D at the particles' current positions).
template <int d>
StructureCouplingSetup<d> buildStructureCoupling(const World<d>& world, const MacGrid<d>& grid, bool viscous,
                                                 double dt, ForceModelCache<d>& models);

template <int d>
class FsiHalfStep final : public System<d> {
 public:
  std::string name() const override { return "fsi_half_step"; }
  Stage stage() const override { return Stage::AdvanceVelocityHalf; }
  std::vector<std::string> reads() const override { return {MacGrid<d>::kName, FluidMaterial::kName}; }
  std::vector<std::string> writes() const override {
    return {RigidBody<d>::kName, Particles<d>::kName, FluidCoupling<d>::kName, "diagnostics"};
  }
  bool needed(const World<d>& w) const override {
    return w.template count<MacGrid<d>>() > 0 && w.template count<FluidCoupling<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  ForceModelCache<d> cache_;
};

template <int d>
class FluidStructureProjection final : public System<d> {
 public:
  std::string name() const override { return "project_fluid_structure"; }
  Stage stage() const override { return Stage::AdvanceVelocity; }
  std::vector<std::string> reads() const override { return {FluidMaterial::kName}; }
  std::vector<std::string> writes() const override {
    return {MacGrid<d>::kName, RigidBody<d>::kName, Particles<d>::kName, FluidCoupling<d>::kName, "diagnostics"};
  }
  bool needed(const World<d>& w) const override {
    return w.template count<MacGrid<d>>() > 0 && w.template count<FluidCoupling<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;
  double unitCflDt(const World<d>& world) const override;  // dx / fastest coupled body point

 private:
  ForceModelCache<d> cache_;
};

}  // namespace monolith
