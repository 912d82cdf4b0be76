#pragma once
// Cloth as a triangle shell of springs, entity-free (thesis Ch. 4 Fig. 4.4; the mass–spring
// cloth of Bridson et al. 2002 [27] Sec. 3 with its simplest bending model):
//  * stretch: one spring per triangle edge, k = stretch stiffness, rest length at rest;
//  * bending: one spring per interior edge between the two vertices opposite it (the two
//    triangles' far corners), k = bend stiffness: it resists folding about the edge (and, weakly,
//    stretching across it); a dihedral-angle bending force is not built;
//  * damping: each spring damped at the over-damping fraction of its critical damping
//    (Sec. 5.11.5), and optional mass damping; both implicit through the deformables' CG.
// Masses are lumped: a third of each triangle's area times the areal density on each vertex.
#include <string>
#include <vector>

#include "solvers/deformable/elasticity.h"

namespace monolith::solvers::deformable {

struct ClothMeshData {
  std::vector<VecD<3>> x;
  std::vector<int> triangles;  // 3 per triangle
  int triangleCount() const { return static_cast<int>(triangles.size()) / 3; }
};

// A rectangular sheet [-a, a] x {0} x [-b, b] in the xz-plane (normal +y), cells of edge ~h
// split into two triangles with the diagonal alternating cell by cell (no preferred shear
// direction).
ClothMeshData sheetMesh(double halfX, double halfZ, double h);

// "" when valid, else the first fault: an index out of range, a repeated vertex or a degenerate
// (zero-area) triangle, an unused vertex, an edge shared by more than two triangles.
std::string clothProblem(const ClothMeshData& m);

struct ClothParameters {
  double density = 0.1;  // kg / m^2
  double stretchStiffness = 1e3, bendStiffness = 0, overdamping = 0, rayleighAlpha = 0;
};

std::vector<double> clothMasses(const std::vector<double>& restX, const std::vector<int>& triangles, double density);

// The spring force model (Model::Springs) of the cloth; `masses` one per particle.
ForceModel<3> clothForceModel(const std::vector<double>& restX, const std::vector<int>& triangles,
                              const ClothParameters& parameters, const std::vector<double>& masses);

// The interior edges' opposite-vertex pairs (2 indices each), in edge order.
std::vector<int> bendingPairs(const std::vector<int>& triangles);

}  // namespace monolith::solvers::deformable
