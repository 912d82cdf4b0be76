#pragma once
// The Newmark stages of Ch. 4 for deformable solids, beside the rigid ones (thesis Sec. 4.2,
// 4.3, 4.6, 4.7; Bridson, Marino, Fedkiw 2003 [28]). Elastic forces are explicit, damping
// forces implicit (a symmetric positive definite solve by CG, solvers/fluid/krylov.h):
//  Step I   (advance_deformable_velocity_half): (M - dt/2 D(x^n)) v^{n+1/2} = M v^n + dt/2 f(x^n)
//  Step IV  (advance_deformable_positions):     x^{n+1} = x^n + dt v^{n+1/2}
//  Step V   (advance_deformable_velocity):      trapezoid rule in the damping,
//           v^{n+1} = v^{n+1/2} + dt/2 M^{-1} (f(x^{n+1}) + D (v^{n+1/2} + v^{n+1})/2),
//           taken as backward Euler over dt/4 to the average u = (v^{n+1/2} + v^{n+1})/2,
//           (M - dt/4 D) u = M v^{n+1/2} + dt/4 f(x^{n+1}), then extrapolated v^{n+1} = 2u - v^{n+1/2}
//           (Sec. 4.7: "a backward Euler solve followed by extrapolation", as in [138]).
// f holds the elastic forces and gravity m g. Without damping Steps I, IV, V are velocity
// Verlet (symplectic: the energy oscillates but does not drift). Fixed particles are
// constrained in both solves by the projection P (zeroing their velocity components), applied to
// the right-hand side and inside CG so that P^T A P stays symmetric (Sec. 4.7.3). The dynamic
// rigid bodies that particles are bound to or held against are unknowns of the same solve
// (solvers/deformable/coupled_damping.h): bodies tied through one rigid body are solved together.
#include <cstdint>
#include <memory>
#include <unordered_map>

#include "components/deformable.h"
#include "components/collider.h"
#include "components/kinematic.h"
#include "components/rigid_body.h"
#include "components/shape.h"
#include "ecs/system.h"
#include "solvers/deformable/elasticity.h"

namespace monolith {

template <int d>
class DampingSolveContacts;

// The force model of a body, built from its components (rest data, masses, material).
template <int d>
solvers::deformable::ForceModel<d> forceModelOf(const Particles<d>& p, const SimplexMesh<d>& mesh, const Elasticity& e);

// Keeps one force model per body (the rest data never changes).
template <int d>
class ForceModelCache {
 public:
  const solvers::deformable::ForceModel<d>& get(Entity e, const Particles<d>& p, const SimplexMesh<d>& m,
                                                const Elasticity& el);

 private:
  std::unordered_map<std::uint64_t, solvers::deformable::ForceModel<d>> models_;
};

struct ImplicitSolveReport {
  int iterations = 0;
  double relativeResidual = 0;
  bool converged = true;  // CG met its tolerance on the projected system
};

// A particle in contact held along one direction during the damping solve (Sec. 4.7.1, 4.7.3:
// contact as a temporary normal joint projected inside CG). Against a static or kinematic body
// (`rigid` invalid): u . normal = velocity. Against a dynamic rigid body `rigid`, which then is
// an unknown of the solve: (u - v_c - w_c x r) . normal = velocity, r from the body's centre of
// mass to the particle.
template <int d>
struct NormalConstraint {
  int particle = 0;
  Vec<d> normal = Vec<d>::Zero();  // unit
  double velocity = 0;
  Entity rigid;
};

// One body alone (solvers/deformable/coupled_damping.h without rigid unknowns): solves
// (M - h D(x)) u = M v + h f with the fixed and bound particles' u prescribed (their current v)
// and projected out of the solve; u returned in `u`, and D u in `dampingForce` if given.
// `rotations`: the damping rotations at the current positions if already known (explicitForces).
// `normals`: particles whose normal velocity is prescribed inside the solve (P = 1 - n n^T on
// them, symmetric in the mass inner product; their `rigid` must be invalid); the constraint only
// steers the damping force: the free particles' returned u is v + h M^{-1} (f + D u), the
// projection undone (Sec. 4.7.2, notes 2.4 step 3), so that contact and friction act afterwards
// as a post-process that passes momentum both ways (without holds this is the solution itself up
// to CG's tolerance, and makes the momentum change exactly h sum f). The stage systems solve the
// bodies tied to dynamic rigid bodies together with those bodies' twists as unknowns.
template <int d>
ImplicitSolveReport implicitDampingSolve(const solvers::deformable::ForceModel<d>& fm, const Particles<d>& p,
                                         const std::vector<double>& f, double h, std::vector<double>& u,
                                         std::vector<double>* dampingForce = nullptr,
                                         const std::vector<solvers::deformable::MatD<d>>* rotations = nullptr,
                                         const std::vector<NormalConstraint<d>>* normals = nullptr);

// Elastic forces plus gravity at the particles' current positions (zero on fixed particles);
// with `rotations` given, also the damping rotations there (one decomposition per element).
template <int d>
std::vector<double> explicitForces(const solvers::deformable::ForceModel<d>& fm, const Particles<d>& p,
                                   const Vec<d>& gravity,
                                   std::vector<solvers::deformable::MatD<d>>* rotations = nullptr);

template <int d>
class AdvanceDeformableVelocity final : public System<d> {
 public:
  explicit AdvanceDeformableVelocity(Stage s);
  ~AdvanceDeformableVelocity() override;
  std::string name() const override {
    return stage_ == Stage::AdvanceVelocityHalf ? "advance_deformable_velocity_half" : "advance_deformable_velocity";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override {
    return {SimplexMesh<d>::kName, Elasticity::kName,         Shape<d>::kName,
            Collider<d>::kName,    KinematicMotion<d>::kName, EmbeddedBinding<d>::kName,
            RigidBinding<d>::kName, "rigid_forces"};
  }
  std::vector<std::string> writes() const override {
    return {Particles<d>::kName, RigidBody<d>::kName, "diagnostics"};  // bodies: damping on bound particles
  }
  bool needed(const World<d>& w) const override { return w.template count<Particles<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;
  // The explicit-elasticity limit (solvers/deformable/stable_step.h) of the stiffest body: with
  // "time": {"cfl": c} a frame is split into substeps of at most c times it (Table 4.1).
  double unitCflDt(const World<d>& world) const override;

 private:
  Stage stage_;
  mutable ForceModelCache<d> cache_;  // rest data only: filling it does not change the state
  std::unique_ptr<DampingSolveContacts<d>> contacts_;  // particle contacts held in the solve
};

template <int d>
class AdvanceDeformablePositions final : public System<d> {
 public:
  std::string name() const override { return "advance_deformable_positions"; }
  Stage stage() const override { return Stage::AdvancePositions; }
  std::vector<std::string> reads() const override { return {}; }
  std::vector<std::string> writes() const override { return {Particles<d>::kName}; }
  bool needed(const World<d>& w) const override { return w.template count<Particles<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;
};

// Kinetic, gravitational and elastic energy and the momenta of the particles, added to the
// standard metrics columns (the rigid bodies' are added by rigid_diagnostics).
template <int d>
class DeformableDiagnostics final : public System<d> {
 public:
  std::string name() const override { return "deformable_diagnostics"; }
  Stage stage() const override { return Stage::Diagnostics; }
  std::vector<std::string> reads() const override {
    return {Particles<d>::kName, SimplexMesh<d>::kName, Elasticity::kName};
  }
  std::vector<std::string> writes() const override { return {"diagnostics"}; }
  bool needed(const World<d>& w) const override { return w.template count<Particles<d>>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  ForceModelCache<d> cache_;
};

struct DeformableTotals {
  double kinetic = 0, potential = 0, elastic = 0;
  Eigen::Vector3d linearMomentum = Eigen::Vector3d::Zero();
  Eigen::Vector3d angularMomentum = Eigen::Vector3d::Zero();
};
// Serial in pool and particle order (deterministic). Fixed particles count (their v is zero).
// `cache`, if given, keeps the force models between calls (else they are rebuilt).
template <int d>
DeformableTotals measureDeformableTotals(const World<d>& world, ForceModelCache<d>* cache = nullptr);

}  // namespace monolith
