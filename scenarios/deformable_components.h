#pragma once
// The scene's "deformable" entry: a mesh (built in, or read from a Gmsh / TetGen file), its
// placement, material and fixed particles; it adds the Particles, SimplexMesh and Elasticity
// components of one body. Also registers the deformable systems of each Newmark stage.
#include "ecs/registry.h"

namespace monolith {

template <int d>
void registerDeformableComponents(Registry& r);
template <int d>
void registerDeformableSystems(Registry& r);
// Step II of particles against rigid bodies: must be registered before the rigid collisions,
// which then read the bodies' velocities it changed.
template <int d>
void registerParticleCollisionSystems(Registry& r);

}  // namespace monolith
