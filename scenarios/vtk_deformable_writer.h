#pragma once
// Deformable bodies as VTK XML UnstructuredGrid (.vtu) frames, every body of the scene in one
// file: tetrahedra (3-D) or triangles (2-D, z = 0). Point data: velocity, mass, fixed, body
// (the entity index). Cell data per element: volume_ratio J = det F, strain (the largest
// |s_i - 1| over the principal stretches s_i of F), von_mises (of the Cauchy stress P F^T / J of
// the body's constitutive model; zero for mass-spring bodies). Cloth (3-D) adds its triangles:
// volume_ratio is the area ratio, strain the largest |s_i - 1| of the in-plane stretches, von_mises
// zero (springs).
#include <string>

#include "ecs/world.h"

namespace monolith {

template <int d>
void writeDeformableFrame(const World<d>& world, const std::string& path);

}  // namespace monolith
