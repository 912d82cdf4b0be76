#pragma once
// The scene's "deformable" entry: a mesh (built in, or read from a Gmsh / TetGen file), its
// placement, material and fixed particles; it adds the Particles, SimplexMesh and Elasticity
// components of one body. Also registers the deformable systems of each Newmark stage.
#include "components/deformable.h"
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
// Particles embedded in other deformables follow their host elements at the end of Steps IV and
// V: registered after every other system that moves particles.
template <int d>
void registerEmbeddingSystems(Registry& r);

// One system of type S, as the registry's system factories return it.
template <class S, class... Args>
std::vector<std::unique_ptr<System<S::dimension>>> singleSystem(Args... args) {
  std::vector<std::unique_ptr<System<S::dimension>>> v;
  v.push_back(std::make_unique<S>(args...));
  return v;
}

// The entry's "fixed": [{min, max}, ...]: particles inside any world box are held in place.
template <int d>
void parseFixedParticles(const Config& c, Particles<d>& p);
// The entry's "bind": [{body, min, max}, ...]: particles inside the world box are hard-bound to
// the rigid body named (listed earlier); adds the RigidBinding component. Without
// `dynamicBodies` only static and kinematic bodies are accepted.
template <int d>
void parseRigidBindings(World<d>& world, Entity e, const Config& c, Particles<d>& p, bool dynamicBodies);
// The entry's "embed": [{body, min, max}, ...]: free particles inside the world box are embedded
// in the elements of the deformable body named (listed earlier) that contain them; adds the
// EmbeddedBinding component and the particles' mass to the host's (barycentric weights).
template <int d>
void parseEmbeddedBindings(World<d>& world, Entity e, const Config& c, Particles<d>& p);

}  // namespace monolith
