#pragma once
// Scene parser of the two_phase_flow component (thesis Ch. 6) and its registration.
#include "ecs/registry.h"

namespace monolith {

template <int d>
void registerSurfaceTensionComponents(Registry& registry);

}  // namespace monolith
