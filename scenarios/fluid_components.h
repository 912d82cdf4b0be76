#pragma once
// Scene parsers of the fluid components (mac_grid, fluid_material) and their registration.
#include "ecs/registry.h"

namespace monolith {

template <int d>
void registerFluidComponents(Registry& registry);
// fluid_coupling, registered after the rigid and deformable components it reads.
template <int d>
void registerFluidCouplingComponent(Registry& registry);

}  // namespace monolith
