#pragma once
// VTK XML ImageData (.vti) frames of a MAC grid for ParaView: cell data velocity (face
// velocities averaged to cell centres), pressure, divergence (area-weighted flux / volume),
// vorticity (z component in 2-D, vector in 3-D) and the solid flag.
#include <string>

#include "ecs/world.h"

namespace monolith {

template <int d>
bool writeMacGridFrame(const World<d>& world, const std::string& path);  // false: no grid

}  // namespace monolith
