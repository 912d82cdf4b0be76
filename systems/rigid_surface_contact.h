#pragma once
// Rigid bodies against the faces of colliding deformable surfaces (cloth triangles, the boundary
// triangles of solids with a surface_collision; segments in 2-D): a body's feature deepest in
// each nearby face, with impulses spread on the face's particles by barycentric weights
// (solvers/deformable/rigid_face_contact.h). Beside the particle/rigid contact
// (systems/particle_contact.h), which touches the same surfaces at their particles only, so that a
// body smaller than a face cannot pass between them. One system per stage, as the particles':
//  * rigid_surface_collisions (Step II, Sec. 4.4): at the candidate positions x^n + dt v^{n+1/2}
//    and the bodies' candidate poses, two-way (equal and opposite impulses, the body with its
//    mass and inertia), registered with the particles' collisions before the rigid contact (whose
//    workspace holds the bodies' velocities from its Step II to Step IV) and so before the
//    surface collisions, which see the changed velocities;
//    and, swept, where a body's centre would pass through a face between x^n and the candidate
//    position (findSweptFaceContacts): a fast or small body cannot tunnel through in one step;
//  * rigid_surface_contact (Step III, Sec. 4.5): the same with the bodies immovable; the
//    particles' velocities only steer the position update (particle_push_out restores them);
//  * rigid_surface_push_out (Step IV, Sec. 4.6.1): a face point inside a body at x^{n+1} is moved
//    to its surface by moving the face's particles (the body stays);
//  * rigid_surface_velocity_contact (Step V): two-way at x^{n+1}, after the velocity update.
// Contacts are found per body in face order, each (body, face) pair's deepest point on both threads
// into its own slot, and applied serially (Gauss-Seidel, forward and backward sweeps), so results
// are the same on any number of threads.
#include <memory>

#include "components/collider.h"
#include "components/surface_collision.h"
#include "solvers/deformable/rigid_face_contact.h"
#include "systems/deformable_self_collision.h"
#include "systems/particle_contact.h"

namespace monolith {

template <int d>
class RigidSurfaceContact final : public System<d> {
 public:
  explicit RigidSurfaceContact(Stage s) : stage_(s) {}
  std::string name() const override {
    switch (stage_) {
      case Stage::Collisions: return "rigid_surface_collisions";
      case Stage::Contact: return "rigid_surface_contact";
      case Stage::AdvancePositions: return "rigid_surface_push_out";
      default: return "rigid_surface_velocity_contact";
    }
  }
  Stage stage() const override { return stage_; }
  std::vector<std::string> reads() const override {
    return {Shape<d>::kName, Collider<d>::kName, KinematicMotion<d>::kName, SurfaceCollision::kName,
            SimplexMesh<d>::kName, "cloth_mesh"};
  }
  std::vector<std::string> writes() const override { return {Particles<d>::kName, RigidBody<d>::kName, "diagnostics"}; }
  bool needed(const World<d>& w) const override {
    return w.template count<SurfaceCollision>() > 0 && w.template count<Collider<d>>() > 0;
  }
  void run(World<d>& world, StepContext& ctx) override;

 private:
  Stage stage_;
  SurfaceCache<d> surfaces_{false};
  PreparedShapes<d> shapes_;
  solvers::deformable::Bvh<d> tree_;
  // Kept from step to step so that a step allocates nothing once warm (the step's data only:
  // every stage gathers them anew, so checkpoints need none of them).
  std::vector<solvers::deformable::RigidFaceBody<d>> bodies_;
  std::vector<RigidBody<d>*> owners_;
  SurfaceParticles<d> particles_;
  std::vector<double> at_;
  solvers::deformable::FaceContactWorkspace<d> work_;
  std::vector<solvers::deformable::FaceContact<d>> contacts_, swept_;
  solvers::deformable::Bvh<d> sweptTree_;  // over the faces' boxes swept over the step
};

// One system per stage listed (Collisions, Contact, AdvancePositions, AdvanceVelocity).
template <int d>
std::vector<std::unique_ptr<System<d>>> makeRigidSurfaceContactSystems(const std::vector<Stage>& stages);

}  // namespace monolith
