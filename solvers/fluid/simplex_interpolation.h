#pragma once
// Barycentric interpolation on a deformable structure's simplex mesh at points of a MAC grid,
// knowing nothing of entities (thesis Sec. 5.4.3: for particles R = I and J_hat holds the
// interpolation weights, so J = N J_hat and J^T spreads a face impulse to the particles with the
// very weights that interpolate their velocity to the face).
//
//  * cellsInside: the structure cells of the staircase (Sec. 5.4.1), cells whose centre lies in
//    an element (the first element in index order wins on shared boundaries);
//  * weightsAt: the d+1 particles and weights of the element containing a point, or, for a
//    point just outside the mesh (a coupling face centre half a cell outside its cell), of the
//    element with the largest smallest barycentric coordinate, its negative coordinates clamped
//    to zero and the rest renormalised: the weights are nonnegative and sum to 1;
//  * rayEntry: where a segment enters the mesh (the walls of the tangential coupling at the
//    structure's true surface, systems/fluid_structure_coupling.cpp).
// Elements are bucketed by the cells their bounding box (grown by one cell) overlaps, so a
// lookup tests only the elements near the point. Periodic wrap-around is not followed: the mesh
// must not cross a periodic side.
#include <array>
#include <vector>

#include <Eigen/Core>

#include "solvers/mac_layout.h"

namespace monolith::solvers {

template <int d>
struct SimplexWeights {
  std::array<int, d + 1> particle{};
  std::array<double, d + 1> weight{};
};

template <int d>
class SimplexLocator {
 public:
  using Vec = Eigen::Matrix<double, d, 1>;
  // x: d numbers per particle; elements: d+1 particle indices per element. Keeps a copy.
  SimplexLocator(const std::vector<double>& x, const std::vector<int>& elements, const MacLayout<d>& layout);
  int elementCount() const { return static_cast<int>(elements_.size()) / (d + 1); }
  // Per cell of the layout: the element containing its centre, -1 if none.
  std::vector<int> cellsInside() const;
  // Barycentric coordinates of p in element e (sum 1; all >= 0 inside).
  Eigen::Matrix<double, d + 1, 1> barycentric(int e, const Vec& p) const;
  SimplexWeights<d> weightsAt(const Vec& p) const;
  // Distance t in [0, tMax] at which p + t e (|e| = 1) enters the mesh: 0 if p is inside, +inf on
  // a miss. Exact: the barycentric coordinates are affine along the segment.
  double rayEntry(const Vec& p, const Vec& e, double tMax) const;

 private:
  int bucketOf(const Vec& p) const;
  std::vector<double> x_;
  std::vector<int> elements_;
  MacLayout<d> layout_;
  std::vector<int> bucketStart_, bucketElements_;  // CSR: per cell, the nearby elements
};

}  // namespace monolith::solvers
