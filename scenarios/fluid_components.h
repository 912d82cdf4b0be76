#pragma once
// Scene parsers of the fluid components (mac_grid, fluid_material) and their registration.
#include "ecs/registry.h"

namespace monolith {

template <int d>
void registerFluidComponents(Registry& registry);

}  // namespace monolith
