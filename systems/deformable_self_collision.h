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
#include <utility>
#include <vector>

#include "components/deformable.h"
#include "components/surface_collision.h"
#include "ecs/system.h"
#include "solvers/deformable/proximity.h"

namespace monolith {

template <int d>
class DeformableSelfCollision final : public System<d> {
 public:
  explicit DeformableSelfCollision(Stage s) : stage_(s) {}
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
  // The joint surface of the colliding bodies, rebuilt when the set of bodies changes.
  std::vector<std::pair<std::uint64_t, int>> bodies_;
  solvers::deformable::CollisionSurface<d> surface_;
};

}  // namespace monolith
