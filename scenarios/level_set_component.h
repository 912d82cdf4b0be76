#pragma once
// Scene parser of the "level_set" component (components/level_set.h): a body's geometry as a
// sampled signed distance, given sample by sample (inline or in a JSON file) or built from a
// closed polygon (2-D) or triangle mesh (3-D, OBJ).
#include "ecs/registry.h"

namespace monolith {

template <int d>
void parseLevelSetComponent(World<d>& world, Entity e, const Config& c);

}  // namespace monolith
