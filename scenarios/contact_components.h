#pragma once
// Scene parsers of the geometry and contact components (shape, collider, kinematic) of issue 3.
#include "ecs/registry.h"

namespace monolith {

// Reads a "shape" object (all types of components/shape.h) and validates its geometry.
template <int d>
void parseShapeComponent(World<d>& world, Entity e, const Config& c);

// Registers "collider" and "kinematic" (after "rigid_body", whose entities they extend).
template <int d>
void registerContactComponents(Registry& registry);

}  // namespace monolith
