#pragma once
// The scene's "cloth" entry (3-D): a triangle shell of springs (components/cloth.h) with its
// particles, placement, fixed and bound particles; and "surface_collision" (any dimension), which
// puts a deformable or cloth entity's surface into the deformable–deformable and self collisions.
// Also registers their systems.
#include "ecs/registry.h"

namespace monolith {

void registerClothComponents(Registry& r);
void registerClothSystems(Registry& r);
template <int d>
void registerSurfaceCollision(Registry& r);
// Step II of the rigid bodies against surface faces: registered with the particles' Step II,
// before the rigid contact (whose workspace carries the bodies' velocities from its Step II on).
template <int d>
void registerRigidSurfaceCollisionSystems(Registry& r);
// Registered after the deformables' systems: each runs after particle contact in its stage.
template <int d>
void registerSelfCollisionSystems(Registry& r);

}  // namespace monolith
