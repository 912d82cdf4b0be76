#pragma once
// Scene parsers of the geometry and contact components (shape, collider, kinematic).
#include <string>
#include <vector>

#include "components/shape.h"
#include "ecs/registry.h"

namespace monolith {

// Reads a "shape" object (all types of components/shape.h) and validates its geometry.
template <int d>
void parseShapeComponent(World<d>& world, Entity e, const Config& c);

// A list of at least `minimum` d-vectors, e.g. "vertices": [[0,0,0], [1,0,0], ...], flattened.
template <int d>
std::vector<double> pointList(const Config& c, const std::string& key, int minimum);

// Reads the Wavefront OBJ file named at `key` (relative to the scene file) into shape.vertices
// and shape.triangles ("v x y z" and "f i j k ..." lines; polygons are fanned into triangles).
void readObj(const Config& c, const std::string& key, Shape<3>& shape);

// Registers "collider" and "kinematic" (after "rigid_body", whose entities they extend).
template <int d>
void registerContactComponents(Registry& registry);

}  // namespace monolith
