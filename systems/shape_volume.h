#pragma once
// The volume (area in 2-D) of a body's shape, for the body-volume buoyancy of a coupled body
// (fsi_solver.buoyancy = "body_volume", docs/fsi.md): the weight of the fluid the body displaces is
// rho_f g times this, whatever cells its staircase covers.
#include "components/shape.h"

namespace monolith {

// Exact for disk/sphere, box, 2-D convex polygon, 3-D cylinder and capsule (a cylinder of half
// height h plus two hemispheres), and a 3-D triangle mesh (the magnitude of its signed volume,
// sum over triangles of a . (b x c) / 6: exact for a closed, consistently oriented mesh, either
// orientation). 0 for a shape without a volume here (plane, 3-D convex hull): the caller keeps
// the staircase's buoyancy then.
template <int d>
double shapeVolume(const Shape<d>& shape);

}  // namespace monolith
