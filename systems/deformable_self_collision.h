#pragma once
// Deformable–deformable and self collisions (thesis Ch. 4; Bridson, Fedkiw, Anderson 2002 [27]),
// between the surfaces of every body with a SurfaceCollision component: the boundary triangles of
// tetrahedral solids and the triangles of cloth in 3-D, the boundary segments of triangle solids in
// 2-D (solvers/deformable/proximity.h).
//  * deformable_self_collisions (Step II, after the particles' collisions with rigid bodies):
//    proximity repulsion on v^{n+1/2} at x^n, then the collision passes over
//    [x^n, x^n + dt v^{n+1/2}]; the velocity changes are kept (they are the collision impulses).
//  * deformable_self_contact (Step III, after particle_contact): the collision passes again on
//    the velocities that will move the particles in Step IV, so the contact impulses against
//    rigid bodies cannot push one surface through another. With rigid colliders present these
//    velocities are the steering ones that particle_contact restores after Step IV (as for rigid
//    contact, Sec. 4.5).
// All bodies' particles are gathered into one set in pool order; pairs are found in parallel and
// applied serially in a fixed order, so results are bitwise the same on any number of threads.
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "components/deformable.h"
#include "components/rigid_body.h"
#include "components/surface_collision.h"
#include "ecs/system.h"
#include "solvers/deformable/proximity.h"

namespace monolith {

// The colliding bodies' surfaces (pool order) as one set, rebuilt only when the bodies change;
// with `rigidCentres` the rigid bodies' centres follow as lone points. positions() gathers the
// matching positions.
template <int d>
class SurfaceCache {
 public:
  explicit SurfaceCache(bool rigidCentres) : rigidCentres_(rigidCentres) {}
  const solvers::deformable::CollisionSurface<d>& get(World<d>& world);
  std::vector<double> positions(World<d>& world) const;

 private:
  bool rigidCentres_;
  std::vector<std::pair<std::uint64_t, int>> bodies_;
  solvers::deformable::CollisionSurface<d> surface_;
};

// The colliding bodies' particles joined in pool order (the indices of SurfaceCache's surface):
// positions, velocities and inverse masses (zero for fixed and bound particles); the changed
// velocities or positions are written back to the bodies' Particles.
template <int d>
struct SurfaceParticles {
  std::vector<Particles<d>*> pools;
  std::vector<double> x, v, inverseMass;
  SurfaceParticles() = default;
  explicit SurfaceParticles(World<d>& world) { gather(world); }
  // Joins the colliding bodies' particles again, reusing the vectors' storage.
  void gather(World<d>& world);
  void writeVelocities() const { scatter(v, &Particles<d>::v); }
  void writePositions() const { scatter(x, &Particles<d>::x); }

 private:
  void scatter(const std::vector<double>& joined, std::vector<double> Particles<d>::*field) const;
};

template <int d>
class DeformableSelfCollision final : public System<d> {
 public:
  // `afterCollisions`: shared by the Step II and Step III systems; the velocities Step II left
  // (collision-free), so Step III can skip its passes when nothing changed them since.
  DeformableSelfCollision(Stage s, std::shared_ptr<std::vector<double>> afterCollisions)
      : stage_(s), afterCollisions_(std::move(afterCollisions)) {}
  std::string name() const override {
    return stage_ == Stage::Collisions ? "deformable_self_collisions" : "deformable_self_contact";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override { return {SurfaceCollision::kName, SimplexMesh<d>::kName, "cloth_mesh"}; }
  std::vector<std::string> writes() const override { return {Particles<d>::kName, "diagnostics"}; }
  bool needed(const World<d>& w) const override { return w.template count<SurfaceCollision>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Stage stage_;
  std::shared_ptr<std::vector<double>> afterCollisions_;
  SurfaceCache<d> surfaces_{false};
};

// The state of the check below between its two stages: positions at the start of the step.
struct SurfaceCrossingScratch {
  std::vector<double> x;
};

// A check that nothing passed through a colliding surface during the step: the surface
// particles and the centres of the moving rigid bodies with a collider are moved from their positions at the start of
// the step (saved at forces_at_start) to those at its end, and every point–face and edge–edge
// pair of the colliding surfaces that crosses on the way (continuous detection, as the collision
// pass) is counted in "surface_crossings" (zero when no body passed through a cloth or another
// surface). Never changes the state.
template <int d>
class SurfaceCrossings final : public System<d> {
 public:
  SurfaceCrossings(Stage s, std::shared_ptr<SurfaceCrossingScratch> scratch) : stage_(s), scratch_(std::move(scratch)) {}
  std::string name() const override {
    return stage_ == Stage::ForcesAtStart ? "surface_crossings@n" : "surface_crossings";
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override {
    return {SurfaceCollision::kName, SimplexMesh<d>::kName, "cloth_mesh", Particles<d>::kName, RigidBody<d>::kName};
  }
  std::vector<std::string> writes() const override { return {"diagnostics"}; }
  bool needed(const World<d>& w) const override { return w.template count<SurfaceCollision>() > 0; }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Stage stage_;
  std::shared_ptr<SurfaceCrossingScratch> scratch_;
  SurfaceCache<d> surfaces_{true};
};


}  // namespace monolith
