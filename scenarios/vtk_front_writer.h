#pragma once
// The surface-tension fronts (components/two_phase_flow.h) as VTK XML PolyData (.vtp) frames,
// every two_phase_flow entity of the scene in one file, z = 0: one polyline per loop of the front
// (a closed loop repeats its first point at the end). Point data: velocity (the grid velocity
// interpolated bilinearly at the point), normal (outward unit normal, the mean of the two
// segments' R t), curvature (-(kappa n) . normal from eq. 6.34: 1/r on a counter-clockwise
// circle) and entity (the entity index). Cell data per loop: entity and length.
#include <string>

#include "ecs/world.h"

namespace monolith {

// 2-D scenes only (the two_phase_flow parser refuses 3-D); writes an empty file without fronts.
void writeFrontFrame(const World<2>& world, const std::string& path);

}  // namespace monolith
