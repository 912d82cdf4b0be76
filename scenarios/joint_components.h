#pragma once
// Scene parsers of the articulation components (components/joint.h): "joint" and
// "articulation", in 3-D and (fixed, revolute and prismatic joints) in 2-D.
#include <string>
#include <vector>

#include "ecs/registry.h"

namespace monolith {

template <int d>
void registerJointComponents(Registry& registry);

// After all entities of a scene exist: resolves the joints' body names, turns world-frame
// anchors and axes into body frames at the initial poses, and refuses unknown bodies, a joint
// between two bodies that cannot move, a second "articulation" component and loops of fixed
// joints (they over-constrain), each at its JSON path (entities[i]...). `created` are the
// scene's entities in file order.
template <int d>
void resolveJoints(World<d>& world, const std::string& file, const std::vector<Entity>& created);

}  // namespace monolith
